// A rig's run as library calls: frames matched across camera listings by
// name and by order, the refusals, and the judged calibration of a
// synthetic stereo rig (sim/rig_scenes.h) against its truth.

#include "pipeline/rig_run.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "sim/rig_scenes.h"

namespace puzzlecal {
namespace {

ImageListing Listing(const std::vector<std::string>& images) {
  ImageListing listing;
  listing.images = images;
  return listing;
}

TEST(RigRunTest, HiddenFoldersAreNoCameras) {
  namespace fs = std::filesystem;
  const fs::path root = fs::temp_directory_path() /
                        ("puzzlecal_rig_folders_" + std::to_string(::getpid()));
  fs::remove_all(root);
  for (const char* name : {"cam1", "cam0", ".report.partial", ".git"}) {
    fs::create_directories(root / name);
  }
  std::vector<std::string> folders;
  std::string error;
  ASSERT_TRUE(ListRigCameraFolders(root.string(), &folders, &error)) << error;
  EXPECT_EQ(folders, (std::vector<std::string>{(root / "cam0").string(),
                                               (root / "cam1").string()}));
  fs::remove_all(root / "cam1");
  EXPECT_FALSE(ListRigCameraFolders(root.string(), &folders, &error));
  EXPECT_NE(error.find("1 camera subfolder "), std::string::npos) << error;
  fs::remove_all(root);
}

TEST(RigRunTest, FramesAreMatchedByFileName) {
  const std::vector<ImageListing> listings = {
      Listing({"left/a.png", "left/b.png"}),
      Listing({"right/b.png", "right/c.png"})};
  RigFrames frames;
  std::string error;
  ASSERT_TRUE(
      MatchRigFrames({"left", "right"}, listings, false, &frames, &error))
      << error;
  EXPECT_EQ(frames.num_frames, 3);
  EXPECT_EQ(frames.frame_of_file[0].at("left/a.png"), 0);
  EXPECT_EQ(frames.frame_of_file[0].at("left/b.png"), 1);
  EXPECT_EQ(frames.frame_of_file[1].at("right/b.png"), 1);
  EXPECT_EQ(frames.frame_of_file[1].at("right/c.png"), 2);
}

TEST(RigRunTest, FramesAreMatchedByOrderWhenAsked) {
  const std::vector<ImageListing> listings = {
      Listing({"left/l01.png", "left/l02.png"}),
      Listing({"right/r01.png", "right/r02.png"})};
  RigFrames frames;
  std::string error;
  ASSERT_TRUE(
      MatchRigFrames({"left", "right"}, listings, true, &frames, &error))
      << error;
  EXPECT_EQ(frames.num_frames, 2);
  EXPECT_EQ(frames.frame_of_file[1].at("right/r02.png"), 1);
}

TEST(RigRunTest, ListingsThatCannotBePairedAreRefusedNamingTheCamera) {
  RigFrames frames;
  std::string error;
  EXPECT_FALSE(MatchRigFrames({"left", "right"},
                              {Listing({"left/l01.png", "left/l02.png"}),
                               Listing({"right/r01.png", "right/r02.png"})},
                              false, &frames, &error));
  EXPECT_NE(error.find("camera 'left' shares no frame with another camera"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("--match_by_order"), std::string::npos) << error;
  EXPECT_FALSE(MatchRigFrames(
      {"left", "right"},
      {Listing({"left/l01.png", "left/l02.png"}), Listing({"right/r01.png"})},
      true, &frames, &error));
  EXPECT_NE(error.find("camera 'right' has 1 images, camera 'left' 2"),
            std::string::npos)
      << error;
}

// Rendered photos of the stereo rig, cam1's folder then made a copy of
// cam0's (the same files, byte for byte): refused naming both cameras and
// how many of the frames are copies, by name and by order, not calibrated
// into a rig with a baseline of 0. Two copied photos among cam1's own are
// named. The rendered folders as they are pass.
TEST(RigRunTest, CameraFoldersHoldingTheSamePhotosAreRefused) {
  namespace fs = std::filesystem;
  const fs::path root = fs::temp_directory_path() /
                        ("puzzlecal_rig_copies_" + std::to_string(::getpid()));
  fs::remove_all(root);
  RigRenderSummary summary;
  std::string error;
  ASSERT_TRUE(
      RenderRigScene(StereoPinholeRig(), root.string(), &summary, &error))
      << error;
  const std::vector<std::string> names = {"cam0", "cam1"};
  auto list = [&](std::vector<ImageListing>* listings) {
    listings->assign(2, ImageListing());
    for (size_t c = 0; c < 2; ++c) {
      ASSERT_TRUE(
          ListImages((root / names[c]).string(), &(*listings)[c], &error))
          << error;
    }
  };
  std::vector<ImageListing> listings;
  list(&listings);
  // The frames both cameras saw.
  std::vector<std::string> both;
  for (int f = 0; f < summary.num_frames; ++f) {
    const std::string name = RigFrameFileName(f);
    if (fs::exists(root / "cam0" / name) && fs::exists(root / "cam1" / name)) {
      both.push_back(name);
    }
  }
  ASSERT_GE(both.size(), 6u);
  RigFrames frames;
  ASSERT_TRUE(MatchRigFrames(names, listings, false, &frames, &error)) << error;

  // Two of cam1's photos replaced by cam0's of the same frames.
  for (size_t k : {2, 5}) {
    fs::copy_file(root / "cam0" / both[k], root / "cam1" / both[k],
                  fs::copy_options::overwrite_existing);
  }
  list(&listings);
  EXPECT_FALSE(MatchRigFrames(names, listings, false, &frames, &error));
  EXPECT_EQ(
      error.rfind("cameras 'cam0' and 'cam1' hold the same photos (2 of " +
                      std::to_string(both.size()) +
                      " byte-identical: " + both[2] + ", " + both[5] + ")",
                  0),
      0u)
      << error;
  EXPECT_NE(error.find("replace the copies"), std::string::npos) << error;

  // cam1 a copy of cam0.
  fs::remove_all(root / "cam1");
  fs::copy(root / "cam0", root / "cam1");
  list(&listings);
  const std::string expected =
      "cameras 'cam0' and 'cam1' hold the same photos (" +
      std::to_string(listings[0].images.size()) + " of " +
      std::to_string(listings[0].images.size()) +
      " byte-identical): a rig needs one folder per camera";
  for (bool by_order : {false, true}) {
    EXPECT_FALSE(MatchRigFrames(names, listings, by_order, &frames, &error));
    EXPECT_EQ(error.rfind(expected, 0), 0u) << error;
    EXPECT_NE(error.find("is 'cam1' a copy of 'cam0'?"), std::string::npos)
        << error;
  }
  fs::remove_all(root);
}

// Per camera, the file name of each frame it saw ("" where none).
std::vector<std::vector<std::string>> FrameFiles(
    const std::vector<RigCameraInput>& inputs) {
  std::vector<std::vector<std::string>> frame_files(inputs.size());
  for (size_t c = 0; c < inputs.size(); ++c) {
    for (size_t f = 0; f < inputs[c].frames.size(); ++f) {
      frame_files[c].push_back(inputs[c].frames[f].board_points.empty()
                                   ? ""
                                   : inputs[c].name + "/" +
                                         RigFrameFileName(static_cast<int>(f)));
    }
  }
  return frame_files;
}

TEST(RigRunTest, JudgedStereoRigMeetsTheTruth) {
  const RigSceneSpec scene = StereoPinholeRig();
  const std::vector<RigCameraInput> inputs = RigCorrespondences(scene, 0.05);
  const std::vector<std::vector<std::string>> frame_files = FrameFiles(inputs);
  JudgedRig judged;
  std::string error;
  ASSERT_TRUE(CalibrateAndJudgeRig(scene.board, inputs, frame_files,
                                   RigRunOptions(), &judged, &error))
      << error;
  ASSERT_EQ(judged.result.cameras.size(), 2u);
  const CamFromRigError cam1 = CompareCamFromRig(judged.result.cameras[1],
                                                 scene.cameras[1].cam_from_rig);
  EXPECT_LT(cam1.rotation_deg, 0.01);
  EXPECT_LT(cam1.translation_m, 1e-4);
  ASSERT_EQ(judged.verdicts.size(), 2u);
  for (const Verdict& verdict : judged.verdicts) {
    EXPECT_EQ(verdict.kind, VerdictKind::kGood) << verdict.Line();
  }
  EXPECT_EQ(judged.rig_verdict.kind, "good") << judged.rig_verdict.Line();
  EXPECT_EQ(judged.file.verdict_kind, "good");
  ASSERT_EQ(judged.file.frames.size(), frame_files[0].size());
  EXPECT_EQ(judged.file.frames[0].files[1], "cam1/frame_000.png");
  EXPECT_EQ(judged.file.frames[0].use[0], "used");
  EXPECT_EQ(RigFrameNames(frame_files)[0], "frame_000.png");
}

// The second camera's photos paired with the wrong frames: each pair shows
// the board at two moments, and no relative pose is shared by most frames.
// Refused with that reason, not solved into a rig of noise (a real pair
// shifted by one frame: "did not converge", then with more iterations a
// file with fx = 9.8 px and a 180-degree rotation).
TEST(RigRunTest, FoldersShiftedByOneFrameAreRefusedAsNotOneInstant) {
  const RigSceneSpec scene = StereoPinholeRig();
  std::vector<RigCameraInput> inputs = RigCorrespondences(scene, 0.05);
  std::vector<CalibrationView>& second = inputs[1].frames;
  std::rotate(second.begin(), second.begin() + 1, second.end());
  JudgedRig judged;
  std::string error;
  EXPECT_FALSE(CalibrateAndJudgeRig(scene.board, inputs, FrameFiles(inputs),
                                    RigRunOptions(), &judged, &error));
  EXPECT_NE(error.find("do not agree on one relative pose"), std::string::npos)
      << error;
  EXPECT_NE(error.find("same instants"), std::string::npos) << error;
}

// Two of the second camera's photos swapped: the rig is made from the
// frames that agree, and the verdict names the two that show another
// moment (they were left out before the joint solve, so no transfer error
// names them).
TEST(RigRunTest, TwoSwappedFramesAreLeftOutAndNamedByTheVerdict) {
  const RigSceneSpec scene = StereoPinholeRig();
  std::vector<RigCameraInput> inputs = RigCorrespondences(scene, 0.05);
  std::vector<int> both;
  for (size_t f = 0; f < inputs[0].frames.size(); ++f) {
    if (!inputs[0].frames[f].board_points.empty() &&
        !inputs[1].frames[f].board_points.empty()) {
      both.push_back(static_cast<int>(f));
    }
  }
  ASSERT_GE(both.size(), 6u);
  const int a = both[2], b = both[3];
  std::swap(inputs[1].frames[a], inputs[1].frames[b]);
  JudgedRig judged;
  std::string error;
  ASSERT_TRUE(CalibrateAndJudgeRig(scene.board, inputs, FrameFiles(inputs),
                                   RigRunOptions(), &judged, &error))
      << error;
  const CamFromRigError cam1 = CompareCamFromRig(judged.result.cameras[1],
                                                 scene.cameras[1].cam_from_rig);
  EXPECT_LT(cam1.rotation_deg, 0.01);
  EXPECT_EQ(judged.rig.left_out_frames, (std::vector<int>{a, b}));
  EXPECT_EQ(judged.rig_verdict.kind, "moved-frames")
      << judged.rig_verdict.Line();
  for (int f : {a, b}) {
    EXPECT_NE(judged.rig_verdict.reason.find(RigFrameFileName(f)),
              std::string::npos)
        << judged.rig_verdict.Line();
  }
  EXPECT_NE(judged.rig_verdict.reason.find("another moment"), std::string::npos)
      << judged.rig_verdict.Line();
}

TEST(RigRunTest, OnlyAPlainCheckerboardHasTheHalfTurn) {
  EXPECT_FALSE(RigSymmetryOf(StereoPinholeRig().board).half_turn);
  // 9 x 6 inner corners of 30 mm from (0, 0): the grid's centre is at
  // (4 tiles, 2.5 tiles).
  const Board checkerboard =
      MakeBoard(BoardType::kCheckerboard, 9, 6, Eigen::Vector2i::Zero(), 0.03);
  const RigBoardSymmetry symmetry = RigSymmetryOf(checkerboard);
  EXPECT_TRUE(symmetry.half_turn);
  EXPECT_TRUE(symmetry.centre.isApprox(Eigen::Vector3d(0.12, 0.075, 0)))
      << symmetry.centre.transpose();
}

}  // namespace
}  // namespace puzzlecal
