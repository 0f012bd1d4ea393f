#ifndef PUZZLECAL_SIM_RENDER_H_
#define PUZZLECAL_SIM_RENDER_H_

// Rendering a board through a camera model with exact ground truth.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "camera/camera_models.h"
#include "sim/pixel_rays.h"
#include "target/board.h"

namespace puzzlecal {

// A disc in the image that hides whatever lies behind it (a finger, a clip).
struct Occluder {
  Eigen::Vector2d center_px = Eigen::Vector2d::Zero();  // disc centre, pixels
  double radius_px = 0.0;                               // disc radius, pixels
  double grey = 0.5;  // grey level of the occluder in [0, 1]
};

// How the board is printed on the torus, for refusal tests: the code bits of
// a PuzzleBoard can be replaced by another random code, the print mirrored or
// its contrast inverted. The default is the true pattern.
struct PatternVariant {
  // Seed of a random replacement for the A and B codes; 0 keeps the true codes.
  uint64_t random_code_seed = 0;
  // Mirror the print left-right (x -> cols - 1 - x about the board centre).
  bool mirrored = false;
  // Swap black and white everywhere (tiles and discs).
  bool inverted = false;
};

// Motion during the exposure: the image streaks along a straight line of
// `length_px`, centred on where the board is at the middle of the exposure
// (the truth), so the streak does not move the corners' true positions, it
// only smears them.
struct MotionBlur {
  double length_px = 0.0;  // streak length in pixels; 0 = none; in [0, 200]
  double angle_deg = 0.0;  // its direction: 0 along +x, 90 along +y (down)
};

// Everything that turns the ideal pattern into a realistic 8-bit image.
struct RenderOptions {
  // Supersamples per pixel along each axis (n x n per pixel) for
  // anti-aliasing; in [1, 16].
  int supersampling = 4;
  // Standard deviation of the Gaussian optical blur in pixels; 0 = none.
  double blur_sigma_px = 0.7;
  // Grey level of black print and of white paper in [0, 1] (before lighting,
  // gamma and noise); black < white.
  double black_level = 0.1;
  double white_level = 0.9;
  // Grey level of everything that is not the board, in [0, 1].
  double background_level = 0.45;
  // White paper around the printed pattern, in tiles. The pattern itself
  // ends half a tile outside the outermost inner corners for a PuzzleBoard
  // (docs/puzzleboard.md's half border tiles) and one full tile outside for a
  // plain checkerboard; this margin comes on top. >= 0.
  double paper_margin_tiles = 1.0;
  // Linear lighting gradient across the image: relative change of brightness
  // from the left to the right edge (0 = uniform).
  double lighting_gradient = 0.0;
  // Vignetting: brightness falls as cos^4-like 1 - v * (r / r_max)^2 with the
  // distance r from the image centre; 0 = none, in [0, 1).
  double vignetting = 0.0;
  // Encoding gamma: the output is linear^(1 / gamma), as cameras store
  // images (1 = none, 2.2 brightens the darks); > 0.
  double gamma = 1.0;
  // Standard deviation of additive Gaussian noise as a fraction of the
  // black-white contrast (white_level - black_level); 0 = none.
  double noise_sigma = 0.0;
  // Seed of the noise generator (renders are deterministic).
  uint64_t seed = 1;
  // Full field of view of the lens in degrees: rays more than half of it
  // from the optical axis are black, which draws a fisheye's image circle;
  // 0 = unlimited. In [0, 360].
  double field_of_view_deg = 0.0;
  // Motion blur (after the optical blur).
  MotionBlur motion_blur;
  // Discs drawn over the image after the board (occluders).
  std::vector<Occluder> occluders;
  // True pattern or a variant for refusal tests.
  PatternVariant variant;

  // False with a reason when a field is out of range.
  bool Check(std::string* why = nullptr) const;
};

// One inner corner of the board as the image shows it.
struct TruthCorner {
  Eigen::Vector2i id = Eigen::Vector2i::Zero();  // absolute (col, row) id
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // exact pixel position
  // Exact pixel position, NaN when the model cannot project the corner
  // (behind a pinhole camera).
  // Visible: projects inside the image with a margin of 1 px (x in
  // [0.5, width - 1.5], same for y), the camera looks at the printed side,
  // the pixel's viewing ray is the corner's own (no fold-over of the
  // distortion), it lies inside the lens's field of view (RenderOptions::
  // field_of_view_deg, with a margin of 1 px) and no occluder lies within
  // 1 px of it.
  bool visible = false;
};

// The exact geometry behind a render.
struct RenderTruth {
  Camera camera;  // model, params, size
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
  std::vector<TruthCorner> corners;  // every printed inner corner of the board
};

// What a render did.
struct RenderSummary {
  bool ok = false;                 // an image was produced
  std::string reason;              // why not, naming the offending input
  int num_visible_corners = 0;     // TruthCorner::visible count
  int num_pixels_without_ray = 0;  // pixels the model has no ray for
                                   // (outside a fisheye's image circle)
  int num_pixels_on_board = 0;     // pixels whose centre sees the paper
};

// Renders `board` seen by `camera` from `cam_from_board` into an 8-bit grey
// image (CV_8UC1) of camera.width x camera.height. Each pixel averages
// options.supersampling^2 sub-pixel rays intersected with the board plane.
// Fills `truth` when not null. On bad input returns an empty image and says
// why in `summary`. The camera's pixel rays are cached per thread, so a
// series of renders through one camera unprojects only once.
cv::Mat RenderBoard(const Board& board, const Camera& camera,
                    const Eigen::Isometry3d& cam_from_board,
                    const RenderOptions& options, RenderTruth* truth = nullptr,
                    RenderSummary* summary = nullptr);

// The same with explicitly precomputed rays (rays.camera() is the camera).
cv::Mat RenderBoard(const Board& board, const PixelRayGrid& rays,
                    const Eigen::Isometry3d& cam_from_board,
                    const RenderOptions& options, RenderTruth* truth = nullptr,
                    RenderSummary* summary = nullptr);

// Every printed inner corner of `board` (Board::AllIds order) with its exact
// projection and visibility as TruthCorner defines it.
// `options` supplies the occluders and the field of view.
std::vector<TruthCorner> ProjectBoardCorners(
    const Board& board, const Camera& camera,
    const Eigen::Isometry3d& cam_from_board, const RenderOptions& options);

}  // namespace puzzlecal

#endif  // PUZZLECAL_SIM_RENDER_H_
