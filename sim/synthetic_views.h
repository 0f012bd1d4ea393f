#ifndef PUZZLECAL_SIM_SYNTHETIC_VIEWS_H_
#define PUZZLECAL_SIM_SYNTHETIC_VIEWS_H_

// Synthetic calibration correspondences with known truth, without images: a
// camera, random board poses, the board corners projected through the model
// (only those inside the image), Gaussian corner noise and optional gross
// outliers. Deterministic for a given seed. The solver's and the evidence's
// tests and bench/bench_calib.cc draw their problems from here; render.h
// makes the photos when the detector is part of the question.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>
#include <string>
#include <vector>

#include "camera/calibration_view.h"
#include "camera/camera_models.h"
#include "target/board.h"

namespace puzzlecal {
namespace sim {

struct SyntheticScene {
  Camera camera;
  int board_cols = 11;  // inner corners
  int board_rows = 8;
  double tile = 0.03;  // metres
  int num_views = 20;
  double noise_px = 0.1;        // Gaussian sigma per coordinate
  double outlier_fraction = 0;  // replaced by uniform random pixels
  // Board centre directions up to this angle from the optical axis, degrees.
  double max_direction_deg = 30;
  // Board tilt (angle between its normal and the viewing ray), degrees.
  double min_tilt_deg = 10;
  double max_tilt_deg = 50;
  // Distance of the board centre, in board widths.
  double min_distance = 1.0;
  double max_distance = 2.0;
  // Views need at least this fraction of the board's corners in the image.
  double min_visible_fraction = 1.0;
  // Largest angle of a visible corner from the optical axis, degrees (the
  // lens' half field of view).
  double max_corner_angle_deg = 180;
  // Board plane parallel to the image plane in every view (a degenerate
  // set: the focal length is undetermined).
  bool fronto_parallel = false;
  unsigned seed = 1;
};

struct SyntheticData {
  std::vector<CalibrationView> views;
  std::vector<Eigen::Isometry3d> cam_from_board;
  std::vector<std::vector<Eigen::Vector2d>> exact;  // noise-free pixels
  std::vector<std::vector<bool>> is_outlier;
  int num_corners = 0;
};

// A camera of `model` with the given image size and parameters.
Camera MakeCamera(CameraModelId model, int width, int height,
                  std::vector<double> params);

// A wide-angle lens with strong barrel distortion, 1280 x 960.
Camera TruthRadtan();
// OpenCV's rational model, 1280 x 960.
Camera TruthRational();
// A 190 degree fisheye on a 1600 x 1200 sensor: the image circle is cut by
// the top and bottom edges, the image corners see 114 degrees off the axis.
Camera TruthFisheye190();

// TruthFisheye190 with a distortion kannala-brandt cannot follow: a radial
// bump of `bump_px` pixels around 50 degrees from the axis (a moulded
// asphere's ripple) and a thin-prism term (a decentred element) that moves
// the image by up to `prism_px` pixels at 90 degrees, along +x and -y. Its
// truth is a kannala-brandt-splined camera whose correction samples that
// function on a grid over 1.9 rad, wider than any calibration's grid over
// its observed field, so that the knots of a fitted spline fall elsewhere
// and it can only approximate the truth.
Camera TruthBumpyFisheye(double bump_px = 2.0, double prism_px = 3.0);

// The scene's views: random poses (deterministic for scene.seed), the
// visible corners projected through scene.camera, noise and outliers added.
SyntheticData MakeSyntheticData(const SyntheticScene& scene);

// A deficient start for capture advice: `count` poses with the board's
// centre near the image centre (within 2.5 % of the distance), nearly
// facing the camera (tilts of 6 to 10 degrees, their directions spread
// around), at the distance where the board spans 60 % of the image width
// (pinhole-like: from fx). Deterministic for `seed`.
std::vector<Eigen::Isometry3d> CentredFrontalPoses(const Camera& camera,
                                                   const Board& board,
                                                   int count, unsigned seed);

// The view of every corner of `board` seen from `cam_from_board` that lies
// in front of the board's printed side, inside the image and within the
// radius where the camera's distortion is monotonic, with
// Gaussian noise of noise_px per coordinate drawn from `rng` (two draws per
// corner, row-major). Sets `exact` (optional) to the noise-free pixels.
CalibrationView ProjectBoardView(const Camera& camera, const Board& board,
                                 const Eigen::Isometry3d& cam_from_board,
                                 double noise_px, std::mt19937* rng,
                                 const std::string& name,
                                 std::vector<Eigen::Vector2d>* exact = nullptr);

}  // namespace sim
}  // namespace puzzlecal

#endif  // PUZZLECAL_SIM_SYNTHETIC_VIEWS_H_
