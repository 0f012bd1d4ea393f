// The truth of a rig's clips (sim/video_clip.h RigClipTruth), without
// rendering: every camera sees the one board motion through its
// cam_from_rig, and a camera offset in time shows later instants under the
// same time stamps.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "sim/video_clip.h"

namespace puzzlecal {
namespace {

double PoseDifference(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

TEST(RigClipTruth, EveryCameraSeesTheOneMotionThroughItsPose) {
  const RigClipSpec spec = StereoClip(3.0, 10.0, 320, 240);
  std::string why;
  ASSERT_TRUE(spec.Check(&why)) << why;
  const std::vector<ClipFrameTruth> motion = ClipTruth(spec.clip);
  const std::vector<std::vector<ClipFrameTruth>> truth = RigClipTruth(spec);
  ASSERT_EQ(truth.size(), 2u);
  for (size_t i = 0; i < motion.size(); ++i) {
    EXPECT_LT(PoseDifference(truth[0][i].cam_from_board,
                             motion[i].cam_from_board),
              1e-12);
    EXPECT_LT(PoseDifference(truth[1][i].cam_from_board,
                             spec.cameras[1].cam_from_rig *
                                 motion[i].cam_from_board),
              1e-12);
    EXPECT_EQ(truth[1][i].time_ms, motion[i].time_ms);
    EXPECT_EQ(truth[1][i].motion_blur.length_px,
              motion[i].motion_blur.length_px);
  }
}

TEST(RigClipTruth, AnOffsetCameraShowsLaterInstantsUnderTheSameStamps) {
  const RigClipSpec spec = StereoClip(3.0, 10.0, 320, 240, 200.0);
  const std::vector<ClipFrameTruth> motion = ClipTruth(spec.clip);
  const std::vector<std::vector<ClipFrameTruth>> truth = RigClipTruth(spec);
  const size_t n = motion.size();
  for (size_t i = 0; i + 2 < n; ++i) {
    EXPECT_EQ(truth[1][i].time_ms, motion[i].time_ms);
    EXPECT_LT(PoseDifference(truth[1][i].cam_from_board,
                             spec.cameras[1].cam_from_rig *
                                 motion[i + 2].cam_from_board),
              1e-9)
        << i;
    EXPECT_EQ(truth[1][i].motion_blur.length_px,
              motion[i + 2].motion_blur.length_px);
  }
  // Beyond the path's end the board stays at its end.
  EXPECT_LT(PoseDifference(truth[1][n - 1].cam_from_board,
                           spec.cameras[1].cam_from_rig *
                               motion[n - 1].cam_from_board),
            1e-9);
}

TEST(RigClipSpec, CheckNamesTheField) {
  RigClipSpec spec = StereoClip();
  std::string why;
  spec.time_offset_ms = {0.0};
  EXPECT_FALSE(spec.Check(&why));
  EXPECT_NE(why.find("time_offset_ms"), std::string::npos) << why;
  spec = StereoClip();
  spec.cameras[0].cam_from_rig = spec.cameras[1].cam_from_rig;
  EXPECT_FALSE(spec.Check(&why));
  EXPECT_NE(why.find("cameras[0].cam_from_rig"), std::string::npos) << why;
  spec = StereoClip();
  std::vector<std::string> paths = {"/nonexistent/a.avi"};
  EXPECT_FALSE(RenderRigClip(spec, paths, 1, nullptr, &why));
  EXPECT_NE(why.find("1 files for 2 cameras"), std::string::npos) << why;
}

}  // namespace
}  // namespace puzzlecal
