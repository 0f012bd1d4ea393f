// The rig's frames from videos without videos: pairing frames by time
// stamp (PairFramesByTime) and the choice of rig frames (ChooseRigFrames)
// on synthetic time stamps and board outlines.

#include "pipeline/rig_video.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace puzzlecal {
namespace {

std::vector<double> Times(int count, double period_ms, double offset_ms = 0) {
  std::vector<double> times;
  for (int i = 0; i < count; ++i) times.push_back(offset_ms + i * period_ms);
  return times;
}

TEST(PairFramesByTime, SynchronisedFramesPairOneToOne) {
  const std::vector<double> reference = Times(10, 100.0 / 3);
  // The other camera's clock jitters by up to 3 ms.
  std::vector<double> times = reference;
  for (size_t i = 0; i < times.size(); ++i) times[i] += (i % 3 == 0 ? 3 : -2);
  const std::vector<TimePairing> pairings =
      PairFramesByTime(reference, times, 100.0 / 3 / 4);
  ASSERT_EQ(pairings.size(), times.size());
  for (size_t i = 0; i < pairings.size(); ++i) {
    EXPECT_EQ(pairings[i].reference, static_cast<int>(i));
    EXPECT_NEAR(pairings[i].difference_ms, times[i] - reference[i], 1e-12);
    EXPECT_FALSE(pairings[i].taken);
  }
}

TEST(PairFramesByTime, HalfAFrameApartPairsNoneButKnowsTheNearest) {
  const double period = 100.0;
  const std::vector<double> reference = Times(10, period);
  const std::vector<double> times = Times(10, period, 0.5 * period + 1);
  const std::vector<TimePairing> pairings =
      PairFramesByTime(reference, times, period / 4);
  for (size_t i = 0; i < pairings.size(); ++i) {
    EXPECT_EQ(pairings[i].reference, -1);
    EXPECT_FALSE(pairings[i].taken);
    // 51 ms after frame i, 49 before frame i + 1 (the last: after frame 9).
    const int nearest = i + 1 < reference.size() ? static_cast<int>(i) + 1 : 9;
    EXPECT_EQ(pairings[i].nearest, nearest);
    EXPECT_NEAR(std::abs(pairings[i].difference_ms), i + 1 < 10 ? 49 : 51,
                1e-9);
  }
  // A wider tolerance pairs them; an exact tie goes to the earlier frame.
  const std::vector<TimePairing> wide =
      PairFramesByTime(reference, Times(3, period, 0.5 * period), period);
  EXPECT_EQ(wide[0].reference, 0);
  EXPECT_EQ(wide[1].reference, 1);
}

TEST(PairFramesByTime, AFasterCameraPairsOnlyItsNearestFrame) {
  // Reference at 10 fps, the other camera at 20 fps with its frames 2 ms
  // late: every second frame sits 2 ms from a reference frame, the others
  // 48 ms off.
  const std::vector<double> reference = Times(5, 100);
  const std::vector<double> times = Times(10, 50, 2);
  const std::vector<TimePairing> pairings =
      PairFramesByTime(reference, times, 60);
  for (size_t i = 0; i < pairings.size(); ++i) {
    if (i % 2 == 0) {
      EXPECT_EQ(pairings[i].reference, static_cast<int>(i / 2)) << i;
      EXPECT_FALSE(pairings[i].taken);
    } else {
      EXPECT_EQ(pairings[i].reference, -1) << i;
      EXPECT_TRUE(pairings[i].taken) << i;
    }
  }
  // A nearer later frame displaces an earlier one.
  const std::vector<TimePairing> later =
      PairFramesByTime({100}, {80, 95, 130}, 25);
  EXPECT_EQ(later[0].reference, -1);
  EXPECT_TRUE(later[0].taken);
  EXPECT_EQ(later[1].reference, 0);
  EXPECT_EQ(later[2].reference, -1);
  EXPECT_FALSE(later[2].taken);  // 30 ms: beyond the tolerance anyway
}

TEST(PairFramesByTime, NoReferenceFramesPairNothing) {
  const std::vector<TimePairing> pairings = PairFramesByTime({}, {0, 10}, 5);
  ASSERT_EQ(pairings.size(), 2u);
  EXPECT_EQ(pairings[0].reference, -1);
  EXPECT_EQ(pairings[0].nearest, -1);
}

// An outline (the four corners of the board's image) around `centre`.
BoardOutline OutlineAt(double x, double y, double size = 100) {
  BoardOutline outline;
  outline << x, x + size, x + size, x, y, y, y + size, y + size;
  return outline;
}

RigFrameOutlines Frame(bool seen0, double x0, bool seen1, double x1,
                       int corners = 100) {
  RigFrameOutlines frame;
  frame.seen = {seen0, seen1};
  frame.outlines = {OutlineAt(x0, 100), OutlineAt(x1, 100)};
  frame.corners = corners;
  return frame;
}

TEST(ChooseRigFrames, NearDuplicatesNeedEveryCameraToRepeat) {
  const std::vector<double> diagonals = {800, 800};  // 4 %: 32 px
  const std::vector<RigFrameOutlines> frames = {
      Frame(true, 100, true, 150),   // 0: kept
      Frame(true, 110, true, 160),   // 1: both moved 10 px: duplicate of 0
      Frame(true, 105, true, 300),   // 2: camera 1 moved 150 px: new
      Frame(true, 100, false, 0),    // 3: camera 0 alone, as in 0: duplicate
      Frame(false, 0, true, 155),    // 4: camera 1 alone, as in 0: duplicate
      Frame(true, 400, false, 0),    // 5: camera 0 alone, new pose: kept
      Frame(true, 402, true, 500),   // 6: camera 1 sees it, not in 5: kept
  };
  const RigFrameChoice choice = ChooseRigFrames(frames, diagonals, 0.04, 40);
  EXPECT_EQ(choice.kept, (std::vector<int>{0, 2, 5, 6}));
  EXPECT_EQ(choice.duplicate_of,
            (std::vector<int>{-1, 0, -1, 0, 0, -1, -1}));
  for (const bool not_needed : choice.not_needed) EXPECT_FALSE(not_needed);
}

TEST(ChooseRigFrames, TheCapPrefersFramesSeenByMoreCamerasAndSpreads) {
  const std::vector<double> diagonals = {1000, 1000};
  std::vector<RigFrameOutlines> frames;
  // Ten frames seen by both cameras along a line, 50 px apart; four seen
  // by camera 0 alone far away.
  for (int i = 0; i < 10; ++i) {
    frames.push_back(Frame(true, 50.0 * i, true, 50.0 * i, 100 + i));
  }
  for (int i = 0; i < 4; ++i) {
    frames.push_back(Frame(true, 2000 + 50.0 * i, false, 0, 300));
  }
  const RigFrameChoice choice = ChooseRigFrames(frames, diagonals, 0.01, 3);
  // The start: both cameras, the most corners (frame 9); then the farthest
  // of the frames both see (frame 0), then the middle (4 or 5: 4, the
  // earlier at equal distance).
  EXPECT_EQ(choice.kept, (std::vector<int>{0, 4, 9}));
  for (size_t k = 0; k < frames.size(); ++k) {
    const bool kept = k == 0 || k == 4 || k == 9;
    EXPECT_EQ(choice.not_needed[k], !kept) << k;
    if (!kept) {
      EXPECT_GE(choice.closest[k], 0) << k;
    }
  }
  EXPECT_EQ(choice.closest[1], 0);
  EXPECT_EQ(choice.closest[8], 9);
  // With room for all ten joint frames, the cap takes single-camera ones
  // only after them.
  const RigFrameChoice eleven = ChooseRigFrames(frames, diagonals, 0.01, 11);
  ASSERT_EQ(eleven.kept.size(), 11u);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(eleven.kept[i], i);
  EXPECT_GE(eleven.kept[10], 10);
}

TEST(ChooseRigFrames, DeterministicOnRepeatedCalls) {
  const std::vector<double> diagonals = {800, 800};
  std::vector<RigFrameOutlines> frames;
  for (int i = 0; i < 30; ++i) {
    frames.push_back(Frame(i % 5 != 0, 37.0 * ((i * 7) % 13), i % 7 != 0,
                           41.0 * ((i * 5) % 11), 50 + i % 4));
  }
  const RigFrameChoice a = ChooseRigFrames(frames, diagonals, 0.02, 6);
  const RigFrameChoice b = ChooseRigFrames(frames, diagonals, 0.02, 6);
  EXPECT_EQ(a.kept, b.kept);
  EXPECT_EQ(a.duplicate_of, b.duplicate_of);
  EXPECT_EQ(a.kept.size(), 6u);
}

TEST(RigVideoOptions, Check) {
  RigVideoOptions options;
  EXPECT_TRUE(options.Check());
  options.max_time_difference_ms = -1;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("max_time_difference_ms"), std::string::npos);
}

}  // namespace
}  // namespace puzzlecal
