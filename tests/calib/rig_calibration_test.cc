// CalibrateRig against the exact truth of sim/ rigs, against
// cv::stereoCalibrate on the same correspondences, and on inputs OpenCV's
// stereo calibration cannot take (cameras that see different corners).

#include "calib/rig_calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <string>

#include "sim/rig_scenes.h"
#include "sim/scenes.h"
#include "target/board.h"
#include "tests/calib/stereo_reference.h"

namespace puzzlecal {
namespace {

// The figures a rig calibration must reach on exact correspondences with
// 0.03 px of corner noise (what the detector reaches on the rig renders,
// see tests/apps/calibrate_rig_test.cc).
constexpr double kMaxRotationErrorDeg = 0.005;
constexpr double kMaxTranslationErrorOfBaseline = 0.001;
constexpr double kMaxFocalRelativeError = 0.0005;
constexpr double kNoisePx = 0.03;

double BaselineOf(const Eigen::Isometry3d& cam_from_rig) {
  return (cam_from_rig.linear().transpose() * cam_from_rig.translation())
      .norm();
}

// Checks every camera of `result` against the truth of `scene`; with
// `sigma_within_limits` also that the standard deviations are below the
// limits (the frames determine the rig well enough to promise them).
void ExpectMatchesTruth(const RigSceneSpec& scene,
                        const RigCalibrationResult& result,
                        bool sigma_within_limits = true) {
  ASSERT_EQ(result.cameras.size(), scene.cameras.size());
  for (size_t c = 0; c < scene.cameras.size(); ++c) {
    SCOPED_TRACE("camera " + scene.cameras[c].name);
    const RigCameraResult& cam = result.cameras[c];
    const Camera& truth = scene.cameras[c].camera;
    for (int k = 0; k < 2; ++k) {
      EXPECT_LT(std::abs(cam.camera.params[k] - truth.params[k]),
                kMaxFocalRelativeError * truth.params[k])
          << "parameter " << k << ": " << cam.camera.params[k] << " vs "
          << truth.params[k];
    }
    if (c == 0) {
      EXPECT_TRUE(cam.cam_from_rig.isApprox(Eigen::Isometry3d::Identity()));
      continue;
    }
    const Eigen::Isometry3d& expected = scene.cameras[c].cam_from_rig;
    const CamFromRigError error = CompareCamFromRig(cam, expected);
    const double rotation_error = error.rotation_deg;
    const double baseline = BaselineOf(expected);
    const double translation_error = error.translation_m;
    EXPECT_LT(rotation_error, kMaxRotationErrorDeg);
    EXPECT_LT(translation_error, kMaxTranslationErrorOfBaseline * baseline)
        << translation_error * 1000 << " mm of a " << baseline * 1000
        << " mm baseline";
    EXPECT_NEAR(cam.baseline_m, baseline,
                kMaxTranslationErrorOfBaseline * baseline);
    // The standard deviations describe the errors: the truth lies within
    // 5 sigma (and the sigma are not absurdly large).
    ASSERT_TRUE(result.covariance_ok);
    EXPECT_GT(cam.rotation_stddev_deg, 0);
    EXPECT_LT(rotation_error, 5 * cam.rotation_stddev_deg + 1e-9);
    EXPECT_LT(std::abs(cam.baseline_m - baseline),
              5 * cam.baseline_stddev_m + 1e-12);
    if (!sigma_within_limits) continue;
    EXPECT_LT(cam.rotation_stddev_deg, kMaxRotationErrorDeg);
    EXPECT_LT(cam.baseline_stddev_m, kMaxTranslationErrorOfBaseline * baseline);
  }
}

RigCalibrationResult CalibrateOrDie(
    const std::vector<RigCameraInput>& inputs,
    const RigCalibrationOptions& options = RigCalibrationOptions()) {
  RigCalibrationResult result;
  std::string error;
  EXPECT_TRUE(CalibrateRig(inputs, options, &result, &error)) << error;
  return result;
}

// A rig whose cameras are calibrated with the splined model (the joint solve
// holds each camera's whole intrinsics as one block, with the spline's
// prior): the rig is recovered as with kannala-brandt, and the covariance
// exists. The lenses are kannala-brandt, so the spline has nothing to add.
TEST(RigCalibrationTest, SplinedCamerasInARig) {
  // Few frames: the joint solve differentiates each corner over the whole
  // 209-value block (about 1 ms per corner and iteration).
  RigSceneSpec scene = StereoFisheyeRig();
  scene.random_frames.count = 10;
  std::vector<RigCameraInput> inputs = RigCorrespondences(scene, kNoisePx, 8);
  for (RigCameraInput& input : inputs) {
    input.model = CameraModelId::kKannalaBrandtSplined;
  }
  const RigCalibrationResult result = CalibrateOrDie(inputs);
  ASSERT_EQ(result.cameras.size(), 2u);
  EXPECT_TRUE(result.covariance_ok);
  const CamFromRigError error =
      CompareCamFromRig(result.cameras[1], scene.cameras[1].cam_from_rig);
  EXPECT_LT(error.rotation_over_sigma, 4.0);
  EXPECT_LT(error.translation_chi2, 3 * 16.0);
  EXPECT_NEAR(result.rms_px, kNoisePx, 0.02);
}

TEST(RigCalibrationTest, StereoPinholeMeetsTheFigures) {
  const RigSceneSpec scene = StereoPinholeRig();
  const std::vector<RigCameraInput> inputs =
      RigCorrespondences(scene, kNoisePx, 7);
  const RigCalibrationResult result = CalibrateOrDie(inputs);
  ExpectMatchesTruth(scene, result);
  EXPECT_NEAR(result.rms_px, kNoisePx, 0.02);
  EXPECT_FALSE(RigCalibrationReport(result).empty());
}

// The stated sigma of cam_from_rig is a promise about the errors: over
// independent draws (frames and noise), the rotation error divided by its
// sigma has an RMS near 1 (the sigma is the RMS length of the small
// rotation), and the translation error's chi-square under its 3 x 3
// covariance averages about 1 per degree of freedom. Ten draws: a ratio off
// by a factor of 2 either way fails (the RMS of ten draws spreads by about
// 25 % at the right sigma).
TEST(RigCalibrationTest, StatedSigmaDescribesTheErrorsOverDraws) {
  constexpr int kDraws = 10;
  double sum_rotation_z2 = 0, sum_translation_chi2 = 0;
  for (int draw = 1; draw <= kDraws; ++draw) {
    SCOPED_TRACE("draw " + std::to_string(draw));
    RigSceneSpec scene = StereoPinholeRig();
    scene.random_frames.seed = 100 + draw;
    const std::vector<RigCameraInput> inputs =
        RigCorrespondences(scene, kNoisePx, draw);
    const RigCalibrationResult result = CalibrateOrDie(inputs);
    ASSERT_TRUE(result.covariance_ok);
    const CamFromRigError error =
        CompareCamFromRig(result.cameras[1], scene.cameras[1].cam_from_rig);
    sum_rotation_z2 += error.rotation_over_sigma * error.rotation_over_sigma;
    sum_translation_chi2 += error.translation_chi2;
  }
  const double rotation_ratio = std::sqrt(sum_rotation_z2 / kDraws);
  const double translation_chi2_per_dof = sum_translation_chi2 / (3 * kDraws);
  EXPECT_GT(rotation_ratio, 0.5);
  EXPECT_LT(rotation_ratio, 2.0);
  EXPECT_GT(translation_chi2_per_dof, 0.25);
  EXPECT_LT(translation_chi2_per_dof, 4.0);
  std::printf(
      "rotation error / sigma RMS %.3f, translation chi-square per "
      "dof %.3f over %d draws\n",
      rotation_ratio, translation_chi2_per_dof, kDraws);
}

TEST(RigCalibrationTest, FisheyeAndPinholeTurned50DegreesMeetTheFigures) {
  const RigSceneSpec scene = FisheyePinholeRig();
  const std::vector<RigCameraInput> inputs =
      RigCorrespondences(scene, kNoisePx, 8);
  // The scene has frames only one of the cameras sees.
  int fisheye_only = 0, pinhole_only = 0, both = 0;
  for (size_t f = 0; f < inputs[0].frames.size(); ++f) {
    const bool a = !inputs[0].frames[f].board_points.empty();
    const bool b = !inputs[1].frames[f].board_points.empty();
    fisheye_only += a && !b;
    pinhole_only += b && !a;
    both += a && b;
  }
  EXPECT_GT(fisheye_only, 0);
  EXPECT_GT(both, 3);
  const RigCalibrationResult result = CalibrateOrDie(inputs);
  ExpectMatchesTruth(scene, result);
  EXPECT_EQ(result.shared_frames(0, 1), both);
  std::cout << "fisheye-only " << fisheye_only << " pinhole-only "
            << pinhole_only << " both " << both << "\n"
            << RigCalibrationReport(result);
}

TEST(RigCalibrationTest, FourCamerasOfThreeModelsMeetTheFigures) {
  const RigSceneSpec scene = FourCameraRig();
  const std::vector<RigCameraInput> inputs =
      RigCorrespondences(scene, kNoisePx, 9);
  const RigCalibrationResult result = CalibrateOrDie(inputs);
  ExpectMatchesTruth(scene, result);
  std::cout << RigCalibrationReport(result);
}

// The +100 degree camera never shares a frame with the reference: its
// starting pose is chained through the +50 degree camera.
TEST(RigCalibrationTest, ChainsThroughAnotherCamera) {
  const RigSceneSpec scene = FourCameraRig();
  std::vector<RigCameraInput> inputs = RigCorrespondences(scene, kNoisePx, 15);
  int removed = 0;
  for (size_t f = 0; f < inputs[0].frames.size(); ++f) {
    if (!inputs[3].frames[f].board_points.empty() &&
        !inputs[0].frames[f].board_points.empty()) {
      inputs[0].frames[f] = CalibrationView{};
      ++removed;
    }
  }
  ASSERT_GT(removed, 0);
  const RigCalibrationResult result = CalibrateOrDie(inputs);
  EXPECT_EQ(result.shared_frames(0, 3), 0);
  EXPECT_EQ(result.start_parent[3], 1);
  // Fewer frames for the reference: sigma of up to 0.0055 degrees, but
  // the errors still meet the figures.
  ExpectMatchesTruth(scene, result, /*sigma_within_limits=*/false);
}

// Two fisheyes 60 degrees apart; in every frame the first keeps only the
// board's left columns and the second only its right ones (overlapping in
// two columns), so no frame has the same corners in both cameras.
TEST(RigCalibrationTest, CamerasSeeingDifferentCornersMeetTheFigures) {
  RigSceneSpec scene = FisheyePinholeRig();
  scene.name = "two_fisheyes";
  scene.cameras[1].camera = FisheyeLensCamera(640, 480, 180.0);
  scene.cameras[1].field_of_view_deg = 180.0;
  scene.cameras[1].cam_from_rig.linear() =
      Eigen::AngleAxisd(-60.0 * M_PI / 180, Eigen::Vector3d::UnitY())
          .toRotationMatrix();
  scene.random_frames.count = 36;
  std::vector<RigCameraInput> inputs = RigCorrespondences(scene, kNoisePx, 10);
  const double split_x = (scene.board.origin.x() + 0.5 * scene.board.cols) *
                         scene.board.tile_size_m;
  for (size_t c = 0; c < 2; ++c) {
    for (CalibrationView& view : inputs[c].frames) {
      CalibrationView kept;
      kept.name = view.name;
      for (size_t i = 0; i < view.board_points.size(); ++i) {
        const double x = view.board_points[i].x() - split_x;
        const double tile = scene.board.tile_size_m;
        if ((c == 0 && x < tile) || (c == 1 && x > -tile)) {
          kept.board_points.push_back(view.board_points[i]);
          kept.image_points.push_back(view.image_points[i]);
        }
      }
      if (kept.board_points.size() < 12) {
        kept.board_points.clear();
        kept.image_points.clear();
      }
      view = kept;
    }
  }
  // cv::fisheye::stereoCalibrate needs the same board points in both
  // cameras; with these frames it refuses.
  std::vector<std::vector<cv::Point3d>> object;
  std::vector<std::vector<cv::Point2d>> left, right;
  int shared = 0;
  for (size_t f = 0; f < inputs[0].frames.size(); ++f) {
    const CalibrationView& a = inputs[0].frames[f];
    const CalibrationView& b = inputs[1].frames[f];
    if (a.board_points.empty() || b.board_points.empty()) continue;
    ++shared;
    EXPECT_NE(a.board_points, b.board_points);
    object.emplace_back();
    left.emplace_back();
    right.emplace_back();
    for (size_t i = 0; i < a.board_points.size(); ++i) {
      object.back().emplace_back(a.board_points[i].x(), a.board_points[i].y(),
                                 0.0);
      left.back().emplace_back(a.image_points[i].x(), a.image_points[i].y());
    }
    for (const Eigen::Vector2d& p : b.image_points) {
      right.back().emplace_back(p.x(), p.y());
    }
  }
  ASSERT_GT(shared, 3);
  cv::Matx33d k1 = cv::Matx33d::eye(), k2 = cv::Matx33d::eye();
  cv::Vec4d d1, d2;
  cv::Mat r, t;
  EXPECT_THROW(cv::fisheye::stereoCalibrate(object, left, right, k1, d1, k2, d2,
                                            cv::Size(640, 480), r, t),
               cv::Exception);

  const RigCalibrationResult result = CalibrateOrDie(inputs);
  ExpectMatchesTruth(scene, result);
}

TEST(RigCalibrationTest, SameRAndTAsOpenCvStereoCalibrate) {
  // Both cameras see the whole board in every frame: far, nearly head on.
  const RigSceneSpec scene = testing::WholeBoardStereoRig();
  testing::SharedStereoFrames shared;
  ASSERT_TRUE(testing::CollectSharedStereoFrames(
      RigCorrespondences(scene, kNoisePx, 11), &shared));
  const std::vector<RigCameraInput>& inputs = shared.inputs;
  const auto& object = shared.object;
  const auto& image = shared.image;
  ASSERT_GE(object.size(), 10u);

  // puzzlecal with OpenCV's objective: plain least squares on every corner.
  RigCalibrationOptions options;
  options.camera.loss = RobustLoss::kNone;
  options.camera.outlier_k = 0;
  const RigCalibrationResult result = CalibrateOrDie(inputs, options);
  ASSERT_TRUE(result.covariance_ok);

  const cv::Size size(scene.cameras[0].camera.width,
                      scene.cameras[0].camera.height);
  const cv::TermCriteria criteria(
      cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-14);
  cv::Mat k[2], d[2];
  for (int c = 0; c < 2; ++c) {
    std::vector<cv::Mat> rvecs, tvecs;
    cv::calibrateCamera(object, image[c], size, k[c], d[c], rvecs, tvecs, 0,
                        criteria);
  }
  cv::Mat r, t, e, fundamental;
  cv::stereoCalibrate(object, image[0], image[1], k[0], d[0], k[1], d[1], size,
                      r, t, e, fundamental, cv::CALIB_USE_INTRINSIC_GUESS,
                      criteria);
  Eigen::Matrix3d r_cv;
  Eigen::Vector3d t_cv;
  cv::cv2eigen(r, r_cv);
  cv::cv2eigen(t, t_cv);

  const RigCameraResult& second = result.cameras[1];
  const double rotation_difference =
      RotationDifferenceDeg(second.cam_from_rig.linear(), r_cv);
  EXPECT_LT(rotation_difference, second.rotation_stddev_deg)
      << "sigma " << second.rotation_stddev_deg << " deg";
  for (int a = 0; a < 3; ++a) {
    EXPECT_LT(std::abs(second.cam_from_rig.translation()(a) - t_cv(a)),
              second.translation_stddev_m(a))
        << "axis " << a << ": " << second.cam_from_rig.translation()(a)
        << " vs " << t_cv(a);
  }
  std::cout << "rotation difference to OpenCV " << rotation_difference
            << " deg (sigma " << second.rotation_stddev_deg
            << "), translation difference "
            << (second.cam_from_rig.translation() - t_cv).norm() * 1000
            << " mm (sigma of the baseline " << second.baseline_stddev_m * 1000
            << " mm)\n";
}

TEST(RigCalibrationTest, CameraThatNeverSharesAFrameIsNamed) {
  const RigSceneSpec scene = StereoPinholeRig();
  std::vector<RigCameraInput> inputs = RigCorrespondences(scene, kNoisePx, 12);
  inputs[1].name = "right_camera";
  // Odd frames only for the first camera, even ones only for the second.
  for (size_t f = 0; f < inputs[0].frames.size(); ++f) {
    inputs[f % 2].frames[f] = CalibrationView{};
  }
  RigCalibrationResult result;
  std::string error;
  EXPECT_FALSE(CalibrateRig(inputs, RigCalibrationOptions(), &result, &error));
  EXPECT_NE(error.find("'right_camera'"), std::string::npos) << error;
  EXPECT_NE(error.find("shares no frame"), std::string::npos) << error;
}

TEST(RigCalibrationTest, MismatchedFrameCountsAreRefused) {
  std::vector<RigCameraInput> inputs =
      RigCorrespondences(StereoPinholeRig(), kNoisePx, 13);
  inputs[1].frames.pop_back();
  RigCalibrationResult result;
  std::string error;
  EXPECT_FALSE(CalibrateRig(inputs, RigCalibrationOptions(), &result, &error));
  EXPECT_NE(error.find("'cam1'"), std::string::npos) << error;
}

TEST(RigCalibrationTest, SameResultWhateverTheThreadCount) {
  const std::vector<RigCameraInput> inputs =
      RigCorrespondences(FisheyePinholeRig(), kNoisePx, 14);
  RigCalibrationOptions one, two;
  one.camera.num_threads = 1;
  two.camera.num_threads = 2;
  const RigCalibrationResult a = CalibrateOrDie(inputs, one);
  const RigCalibrationResult b = CalibrateOrDie(inputs, two);
  for (size_t c = 0; c < a.cameras.size(); ++c) {
    EXPECT_EQ(a.cameras[c].camera.params, b.cameras[c].camera.params);
    EXPECT_EQ(a.cameras[c].param_stddev, b.cameras[c].param_stddev);
    EXPECT_TRUE(a.cameras[c].cam_from_rig.matrix() ==
                b.cameras[c].cam_from_rig.matrix());
  }
}

TEST(RigCalibrationTest, OptionsCheckNamesTheField) {
  RigCalibrationOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why));
  options.min_shared_frames = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("min_shared_frames"), std::string::npos);
}

}  // namespace
}  // namespace puzzlecal

namespace puzzlecal {
namespace {

// A stereo rig looking at a plain 6 x 4 checkerboard (symmetric under half a
// turn) whose second camera labels the board the other way round in some
// frames, as a detector may: its board points turned by half a turn about
// the corner grid's centre.
struct SymmetricBoardRig {
  RigSceneSpec scene;
  std::vector<RigCameraInput> inputs;
  RigBoardSymmetry symmetry;
  std::vector<bool> turned;  // per frame, camera 1's labels turned
};

SymmetricBoardRig MakeSymmetricBoardRig(const std::vector<int>& turned_frames,
                                        bool turn_all = false) {
  SymmetricBoardRig rig;
  rig.scene = StereoPinholeRig();
  rig.scene.board =
      MakeBoard(BoardType::kCheckerboard, 6, 4, Eigen::Vector2i::Zero(), 0.05);
  rig.scene.min_visible_corners = 24;  // the whole board, as a detector needs
  rig.scene.random_frames.count = 20;
  rig.inputs = RigCorrespondences(rig.scene, kNoisePx, 11);
  rig.symmetry.half_turn = true;
  rig.symmetry.centre = Eigen::Vector3d(2.5 * 0.05, 1.5 * 0.05, 0);
  const size_t num_frames = rig.inputs[1].frames.size();
  rig.turned.assign(num_frames, turn_all);
  for (int f : turned_frames) rig.turned[f] = true;
  for (size_t f = 0; f < num_frames; ++f) {
    if (!rig.turned[f]) continue;
    for (Eigen::Vector3d& p : rig.inputs[1].frames[f].board_points) {
      p = Eigen::Vector3d(2 * rig.symmetry.centre.x() - p.x(),
                          2 * rig.symmetry.centre.y() - p.y(), p.z());
    }
  }
  return rig;
}

// The rig of the same correspondences labelled alike in both cameras: a
// resolved ambiguity gives the same calibration.
void ExpectSameAsLabelledAlike(const SymmetricBoardRig& rig,
                               const RigCalibrationResult& result) {
  const SymmetricBoardRig clean = MakeSymmetricBoardRig({});
  RigCalibrationResult expected;
  std::string error;
  ASSERT_TRUE(
      CalibrateRig(clean.inputs, RigCalibrationOptions(), &expected, &error))
      << error;
  EXPECT_NEAR(result.cameras[1].baseline_m, expected.cameras[1].baseline_m,
              1e-7);
  EXPECT_LT(RotationDifferenceDeg(result.cameras[1].cam_from_rig.linear(),
                                  expected.cameras[1].cam_from_rig.linear()),
            1e-5);
  EXPECT_NEAR(result.cameras[1].camera.params[0],
              expected.cameras[1].camera.params[0], 1e-4);
  // And the truth lies within 5 sigma of it.
  const CamFromRigError truth =
      CompareCamFromRig(result.cameras[1], rig.scene.cameras[1].cam_from_rig);
  EXPECT_LT(truth.rotation_over_sigma, 5);
  EXPECT_LT(std::abs(result.cameras[1].baseline_m -
                     BaselineOf(rig.scene.cameras[1].cam_from_rig)),
            5 * result.cameras[1].baseline_stddev_m);
}

int SharedFrames(const std::vector<RigCameraInput>& inputs) {
  int shared = 0;
  for (size_t f = 0; f < inputs[0].frames.size(); ++f) {
    shared += !inputs[0].frames[f].board_points.empty() &&
              !inputs[1].frames[f].board_points.empty();
  }
  return shared;
}

TEST(RigCalibrationTest, SymmetricBoardLabelledTheOtherWayIsTurnedAndUsed) {
  const SymmetricBoardRig rig = MakeSymmetricBoardRig({1, 4, 7, 12});
  const int shared = SharedFrames(rig.inputs);
  ASSERT_GE(shared, 10);
  RigCalibrationResult result;
  std::string error;
  ASSERT_TRUE(CalibrateRig(rig.inputs, rig.symmetry, RigCalibrationOptions(),
                           &result, &error))
      << error;
  EXPECT_EQ(result.shared_frames(0, 1), shared);
  for (size_t f = 0; f < rig.turned.size(); ++f) {
    const bool seen = !rig.inputs[1].frames[f].board_points.empty() &&
                      !rig.inputs[0].frames[f].board_points.empty();
    EXPECT_EQ(result.cameras[1].relabelled[f], rig.turned[f] && seen)
        << "frame " << f;
    if (result.cameras[1].relabelled[f]) {
      EXPECT_NE(result.cameras[1].frame_note[f].find("half a turn"),
                std::string::npos);
    }
  }
  ExpectSameAsLabelledAlike(rig, result);
}

TEST(RigCalibrationTest, SymmetricBoardLabelledTheOtherWayEverywhere) {
  // A camera mounted upside down labels every frame the other way round.
  const SymmetricBoardRig rig = MakeSymmetricBoardRig({}, /*turn_all=*/true);
  RigCalibrationResult result;
  std::string error;
  ASSERT_TRUE(CalibrateRig(rig.inputs, rig.symmetry, RigCalibrationOptions(),
                           &result, &error))
      << error;
  EXPECT_EQ(result.shared_frames(0, 1), SharedFrames(rig.inputs));
  ExpectSameAsLabelledAlike(rig, result);
}

TEST(RigCalibrationTest, WithoutTheSymmetryTheTurnedFramesAreNamed) {
  const SymmetricBoardRig rig = MakeSymmetricBoardRig({1, 4, 7, 12});
  RigCalibrationResult result;
  std::string error;
  ASSERT_TRUE(
      CalibrateRig(rig.inputs, RigCalibrationOptions(), &result, &error))
      << error;
  for (int f : {1, 4, 7, 12}) {
    if (rig.inputs[0].frames[f].board_points.empty() ||
        rig.inputs[1].frames[f].board_points.empty()) {
      continue;
    }
    EXPECT_FALSE(result.cameras[1].frame_used[f]) << "frame " << f;
    EXPECT_NE(result.cameras[1].frame_note[f].find("not used"),
              std::string::npos)
        << result.cameras[1].frame_note[f];
  }
}

}  // namespace
}  // namespace puzzlecal
