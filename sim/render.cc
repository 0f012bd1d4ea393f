#include "sim/render.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "sim/board_pattern.h"
#include "util/failure.h"

namespace puzzlecal {
namespace {

// SplitMix64: a tiny, fully specified generator, so the noise is the same on
// every platform and independent per image row.
uint64_t SplitMix64(uint64_t* state) {
  uint64_t z = (*state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

// Uniform in (0, 1).
double Uniform(uint64_t* state) {
  return ((SplitMix64(state) >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

bool IsFiniteRange(double v, double lo, double hi) {
  return std::isfinite(v) && v >= lo && v <= hi;
}

bool PoseIsValid(const Eigen::Isometry3d& pose, std::string* why) {
  if (!pose.matrix().allFinite()) {
    *why = "cam_from_board has non-finite entries";
    return false;
  }
  const Eigen::Matrix3d r = pose.linear();
  if ((r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
      r.determinant() < 0) {
    *why = "cam_from_board rotation is not a proper rotation";
    return false;
  }
  return true;
}

cv::Mat Fail(RenderSummary* summary, const std::string& reason) {
  summary->ok = false;
  summary->reason = reason;
  return cv::Mat();
}

// True when an occluder of the row may cover part of pixel (x, y).
bool PixelMayBeOccluded(const std::vector<const Occluder*>& occluders, int x,
                        int y) {
  for (const Occluder* o : occluders) {
    const double dx = std::max(std::abs(x - o->center_px.x()) - 0.5, 0.0);
    const double dy = std::max(std::abs(y - o->center_px.y()) - 0.5, 0.0);
    if (dx * dx + dy * dy <= o->radius_px * o->radius_px) return true;
  }
  return false;
}

// The samples of one pixel's n x n grid, in [0, 1) offsets from the pixel's
// top-left corner.
struct SubGrid {
  int n = 1;
  double offset[16] = {};
};

}  // namespace

bool RenderOptions::Check(std::string* why) const {
  if (supersampling < 1 || supersampling > 16) {
    return Fail("supersampling must be in [1, 16]", why);
  }
  if (!IsFiniteRange(blur_sigma_px, 0.0, 50.0)) {
    return Fail("blur_sigma_px must be in [0, 50]", why);
  }
  if (!IsFiniteRange(black_level, 0.0, 1.0) ||
      !IsFiniteRange(white_level, 0.0, 1.0) || !(black_level < white_level)) {
    return Fail(
        "black_level and white_level must be in [0, 1] with "
        "black_level < white_level",
        why);
  }
  if (!IsFiniteRange(background_level, 0.0, 1.0)) {
    return Fail("background_level must be in [0, 1]", why);
  }
  if (!IsFiniteRange(paper_margin_tiles, 0.0, 1000.0)) {
    return Fail("paper_margin_tiles must be in [0, 1000]", why);
  }
  if (!(std::isfinite(lighting_gradient) &&
        std::abs(lighting_gradient) < 2.0)) {
    return Fail("lighting_gradient must be in (-2, 2)", why);
  }
  if (!(std::isfinite(vignetting) && vignetting >= 0.0 && vignetting < 1.0)) {
    return Fail("vignetting must be in [0, 1)", why);
  }
  if (!(std::isfinite(gamma) && gamma > 0.05 && gamma < 20.0)) {
    return Fail("gamma must be in (0.05, 20)", why);
  }
  if (!IsFiniteRange(noise_sigma, 0.0, 10.0)) {
    return Fail("noise_sigma must be in [0, 10]", why);
  }
  if (!IsFiniteRange(field_of_view_deg, 0.0, 360.0)) {
    return Fail("field_of_view_deg must be in [0, 360]", why);
  }
  if (!IsFiniteRange(motion_blur.length_px, 0.0, 200.0) ||
      !std::isfinite(motion_blur.angle_deg)) {
    return Fail("motion_blur: length_px must be in [0, 200], angle_deg finite",
                why);
  }
  for (size_t i = 0; i < occluders.size(); ++i) {
    const Occluder& o = occluders[i];
    if (!o.center_px.allFinite() || !IsFiniteRange(o.radius_px, 0.0, 1e6) ||
        !IsFiniteRange(o.grey, 0.0, 1.0)) {
      return Fail("occluder " + std::to_string(i) +
                      ": center_px must be finite, radius_px >= 0, grey in "
                      "[0, 1]",
                  why);
    }
  }
  return true;
}

std::vector<TruthCorner> ProjectBoardCorners(
    const Board& board, const Camera& camera,
    const Eigen::Isometry3d& cam_from_board, const RenderOptions& options) {
  std::vector<TruthCorner> corners;
  const std::vector<Eigen::Vector2i> ids = board.AllIds();
  corners.reserve(ids.size());
  // The printed side faces the camera when the camera centre lies at z < 0
  // in the board frame (board z points into the page).
  const Eigen::Vector3d center_in_board =
      -(cam_from_board.linear().transpose() * cam_from_board.translation());
  const bool sees_print = center_in_board.z() < 0;
  const double max_radius = MaxMonotonicRadius(camera);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Eigen::Vector2i& id : ids) {
    TruthCorner corner;
    corner.id = id;
    const Eigen::Vector3d point = cam_from_board * board.Point(id);
    Eigen::Vector2d xy;
    if (!camera.Project(point, &xy) || !xy.allFinite()) {
      corner.xy = Eigen::Vector2d(nan, nan);
      corners.push_back(corner);
      continue;
    }
    corner.xy = xy;
    Eigen::Vector3d seen_from = point;  // from the origin of its ray
    bool visible = sees_print && xy.x() >= 0.5 &&
                   xy.x() <= camera.width - 1.5 && xy.y() >= 0.5 &&
                   xy.y() <= camera.height - 1.5;
    if (visible) {
      // The pixel must see this corner along its own ray: strong distortion
      // can fold several rays onto one pixel, and the image shows only one.
      // (For a non-central camera: the ray from the pixel's own origin.)
      ViewingRay ray;
      const UnprojectStatus status = camera.UnprojectRay(xy, &ray);
      seen_from = point - ray.origin;
      const double cos_angle = ray.direction.dot(seen_from.normalized());
      visible = status.converged && cos_angle > std::cos(1e-6) &&
                FieldRadius(camera, seen_from) < max_radius;
    }
    if (visible && options.field_of_view_deg > 0) {
      // One pixel of margin, measured by the model's local ray spread.
      Eigen::Vector3d ray_next;
      camera.Unproject(xy + Eigen::Vector2d(1.0, 0.0), &ray_next);
      const double pixel_angle = std::acos(
          std::clamp(ray_next.dot(seen_from.normalized()), -1.0, 1.0));
      const double angle =
          std::atan2(seen_from.head<2>().norm(), seen_from.z());
      visible =
          std::isfinite(pixel_angle) &&
          angle + pixel_angle < 0.5 * options.field_of_view_deg * M_PI / 180.0;
    }
    for (const Occluder& o : options.occluders) {
      if (visible && (xy - o.center_px).norm() < o.radius_px + 1.0) {
        visible = false;
      }
    }
    corner.visible = visible;
    corners.push_back(corner);
  }
  return corners;
}

cv::Mat RenderBoard(const Board& board, const Camera& camera,
                    const Eigen::Isometry3d& cam_from_board,
                    const RenderOptions& options, RenderTruth* truth,
                    RenderSummary* summary) {
  RenderSummary local_summary;
  if (summary == nullptr) summary = &local_summary;
  *summary = RenderSummary();
  // One grid per thread: a series of renders through one camera pays the
  // iterative unprojection once.
  thread_local PixelRayGrid cached_rays;
  if (!cached_rays.Matches(camera)) {
    std::string why;
    if (!cached_rays.Compute(camera, &why)) return Fail(summary, why);
  }
  return RenderBoard(board, cached_rays, cam_from_board, options, truth,
                     summary);
}

namespace {

// Shades the board as the camera sees it, one pixel at a time, in linear
// grey (before lighting, gamma and noise). Holds what every pixel shares:
// the camera's place in the board frame (lengths in tiles), the pattern and
// the supersampling grid.
class BoardShader {
 public:
  BoardShader(const Board& board, const PixelRayGrid& rays,
              const Eigen::Isometry3d& cam_from_board,
              const RenderOptions& options)
      : rays_(rays),
        options_(options),
        board_from_cam_rotation_(cam_from_board.linear().transpose()),
        center_(-(board_from_cam_rotation_ * cam_from_board.translation()) /
                board.tile_size_m),
        // A non-central camera's rays start at (0, 0, OriginZ) in the
        // camera frame: center + OriginZ * axis in the board frame (tiles).
        axis_(board_from_cam_rotation_.col(2) / board.tile_size_m),
        pattern_(board, options.variant, options.paper_margin_tiles),
        black_value_(center_.z() < 0 ? options.black_level
                                     : options.white_level) {
    sub_.n = options.supersampling;
    for (int i = 0; i < sub_.n; ++i) sub_.offset[i] = (i + 0.5) / sub_.n;
    inv_samples_ = 1.0 / (sub_.n * sub_.n);
  }

  // The linear grey of pixel (x, y); `on_board` is set when its centre sees
  // the board, `has_ray` when the model has a ray at each of its corners.
  // `row_occluders` are the occluders that reach row y.
  float Shade(int x, int y, const std::vector<const Occluder*>& row_occluders,
              bool* on_board, bool* has_ray_out) const {
    *on_board = false;
    const double* corner_rays[4] = {rays_.Ray(x, y), rays_.Ray(x + 1, y),
                                    rays_.Ray(x, y + 1),
                                    rays_.Ray(x + 1, y + 1)};
    bool has_ray = true;
    Eigen::Vector3d b[4], c[4];  // corner ray directions and origins
    for (int k = 0; k < 4; ++k) {
      const Eigen::Map<const Eigen::Vector3d> r(corner_rays[k]);
      if (!r.allFinite()) has_ray = false;
      b[k] = board_from_cam_rotation_ * r;
      c[k] = rays_.central()
                 ? center_
                 : center_ + rays_.OriginZ(x + k % 2, y + k / 2) * axis_;
    }
    *has_ray_out = has_ray;
    // Where the pixel's corner rays meet the board plane (tiles).
    Eigen::Vector2d hit[4];
    int num_hits = 0;
    for (int k = 0; k < 4 && has_ray; ++k) {
      if (!(b[k].z() * c[k].z() < 0)) continue;
      const double t = -c[k].z() / b[k].z();
      hit[k] = c[k].head<2>() + t * b[k].head<2>();
      ++num_hits;
    }
    const bool all_hit = has_ray && num_hits == 4;
    const bool may_be_occluded =
        !row_occluders.empty() && PixelMayBeOccluded(row_occluders, x, y);
    // Sub-pixel rays are convex combinations of the corner rays, so when
    // no corner ray heads towards the plane none does; without rays the
    // model sees nothing. Either way the pixel is background.
    if ((!has_ray || num_hits == 0) && !may_be_occluded) {
      return static_cast<float>(options_.background_level);
    }
    // Board-plane footprint of one sample step (zero = hard samples when
    // a corner ray misses the plane).
    Eigen::Matrix2d footprint = Eigen::Matrix2d::Zero();
    if (all_hit) {
      footprint.col(0) = 0.5 * ((hit[1] - hit[0]) + (hit[3] - hit[2]));
      footprint.col(1) = 0.5 * ((hit[2] - hit[0]) + (hit[3] - hit[1]));
      float value;
      if (!may_be_occluded &&
          ShadeSimplePixel(b, c, hit, footprint, &value, on_board)) {
        return value;
      }
      footprint /= sub_.n;
    }
    const float value = static_cast<float>(
        SupersamplePixel(x, y, b, c, has_ray, footprint, row_occluders));
    if (all_hit) {
      const Eigen::Vector2d mid = 0.25 * (hit[0] + hit[1] + hit[2] + hit[3]);
      *on_board = pattern_.Sample(mid.x(), mid.y()) != BoardInk::kNone;
    }
    return value;
  }

 private:
  double InkValue(BoardInk ink) const {
    switch (ink) {
      case BoardInk::kBlack:
        return black_value_;
      case BoardInk::kWhite:
      case BoardInk::kPaper:
        return options_.white_level;
      case BoardInk::kNone:
        break;
    }
    return options_.background_level;
  }

  double MixValue(const InkMix& mix) const {
    return mix.black * black_value_ + mix.white * options_.white_level +
           mix.none * options_.background_level;
  }

  // Most pixels see one ink only, or one straight edge: shade them without
  // supersamples. False when the pixel needs them. The box of the corner
  // hits is padded for the curvature of distorted pixel footprints.
  bool ShadeSimplePixel(const Eigen::Vector3d b[4], const Eigen::Vector3d c[4],
                        const Eigen::Vector2d hit[4],
                        const Eigen::Matrix2d& footprint, float* value,
                        bool* on_board) const {
    Eigen::Vector2d lo = hit[0], hi = hit[0];
    for (int k = 1; k < 4; ++k) {
      lo = lo.cwiseMin(hit[k]);
      hi = hi.cwiseMax(hit[k]);
    }
    const Eigen::Vector2d pad = 0.25 * (hi - lo);
    lo -= pad;
    hi += pad;
    const BoardPattern::BoxContent content =
        pattern_.Classify(lo.x(), lo.y(), hi.x(), hi.y());
    // Where the pixel centre's ray meets the plane (the centre ray heads
    // towards it: it is a mean of the corner rays).
    const Eigen::Vector3d d_mid = 0.25 * (b[0] + b[1] + b[2] + b[3]);
    const Eigen::Vector3d c_mid = 0.25 * (c[0] + c[1] + c[2] + c[3]);
    const Eigen::Vector2d mid =
        c_mid.head<2>() + (-c_mid.z() / d_mid.z()) * d_mid.head<2>();
    if (content == BoardPattern::BoxContent::kUniform) {
      const BoardInk ink = pattern_.Sample(mid.x(), mid.y());
      *value = static_cast<float>(InkValue(ink));
      *on_board = ink != BoardInk::kNone;
      return true;
    }
    if (content == BoardPattern::BoxContent::kOneEdge) {
      // One straight edge: the exact coverage of the whole pixel's
      // footprint needs no supersamples.
      *value = static_cast<float>(
          MixValue(pattern_.SampleArea(mid.x(), mid.y(), footprint)));
      *on_board = true;
      return true;
    }
    return false;
  }

  // The mean of the pixel's n x n sub-pixel rays (occluders, background
  // where a ray misses the plane or the model has no ray).
  double SupersamplePixel(
      int x, int y, const Eigen::Vector3d b[4], const Eigen::Vector3d c[4],
      bool has_ray, const Eigen::Matrix2d& footprint,
      const std::vector<const Occluder*>& row_occluders) const {
    double sum = 0.0;
    for (int j = 0; j < sub_.n; ++j) {
      const double wy = sub_.offset[j];
      const Eigen::Vector3d left = b[0] + wy * (b[2] - b[0]);
      const Eigen::Vector3d right = b[1] + wy * (b[3] - b[1]);
      const Eigen::Vector3d step = right - left;
      const Eigen::Vector3d origin_left = c[0] + wy * (c[2] - c[0]);
      const Eigen::Vector3d origin_step =
          c[1] + wy * (c[3] - c[1]) - origin_left;
      for (int i = 0; i < sub_.n; ++i) {
        const double wx = sub_.offset[i];
        bool occluded = false;
        for (const Occluder* o : row_occluders) {
          const double dx = x - 0.5 + wx - o->center_px.x();
          const double dy = y - 0.5 + wy - o->center_px.y();
          if (dx * dx + dy * dy < o->radius_px * o->radius_px) {
            sum += o->grey;
            occluded = true;
            break;
          }
        }
        if (occluded) continue;
        if (!has_ray) {
          sum += options_.background_level;
          continue;
        }
        const Eigen::Vector3d d = left + wx * step;
        const Eigen::Vector3d o = origin_left + wx * origin_step;
        // The ray meets the plane z = 0 in front of the camera only when
        // it heads towards it.
        if (!(d.z() * o.z() < 0)) {
          sum += options_.background_level;
          continue;
        }
        const double t = -o.z() / d.z();
        sum += MixValue(pattern_.SampleArea(o.x() + t * d.x(),
                                            o.y() + t * d.y(), footprint));
      }
    }
    return sum * inv_samples_;
  }

  const PixelRayGrid& rays_;
  const RenderOptions& options_;
  const Eigen::Matrix3d board_from_cam_rotation_;
  const Eigen::Vector3d center_;
  const Eigen::Vector3d axis_;
  const BoardPattern pattern_;
  const double black_value_;
  SubGrid sub_;
  double inv_samples_ = 1.0;
};

// The lens's image circle: black beyond half the field of view, with an
// anti-aliased rim one pixel wide (measured by the corner rays' spread).
void ApplyImageCircle(const PixelRayGrid& rays, double field_of_view_deg,
                      cv::Mat1f* linear) {
  const double max_angle = 0.5 * field_of_view_deg * M_PI / 180.0;
  cv::parallel_for_(cv::Range(0, linear->rows), [&](const cv::Range& range) {
    for (int y = range.start; y < range.end; ++y) {
      float* out = linear->ptr<float>(y);
      for (int x = 0; x < linear->cols; ++x) {
        const Eigen::Map<const Eigen::Vector3d> r0(rays.Ray(x, y));
        const Eigen::Map<const Eigen::Vector3d> r3(rays.Ray(x + 1, y + 1));
        const Eigen::Map<const Eigen::Vector3d> r1(rays.Ray(x + 1, y));
        const Eigen::Map<const Eigen::Vector3d> r2(rays.Ray(x, y + 1));
        const Eigen::Vector3d mean = r0 + r1 + r2 + r3;
        if (!mean.allFinite()) {  // no ray: outside the lens as well
          out[x] = 0.0f;
          continue;
        }
        const double angle = std::atan2(mean.head<2>().norm(), mean.z());
        const double pixel_angle = std::max(
            std::acos(std::clamp(r0.dot(r3), -1.0, 1.0)) / std::sqrt(2.0),
            1e-12);
        const double inside =
            std::clamp(0.5 + (max_angle - angle) / pixel_angle, 0.0, 1.0);
        out[x] = static_cast<float>(out[x] * inside);
      }
    }
  });
}

// The kernel of a straight streak of `blur.length_px` through its centre:
// the segment sampled finely, each sample splatted bilinearly, normalised.
// Point-symmetric about the centre, so it moves no edge crossing.
cv::Mat1f MotionKernel(const MotionBlur& blur) {
  const double angle = blur.angle_deg * M_PI / 180.0;
  const double dx = std::cos(angle), dy = std::sin(angle);
  const int half = static_cast<int>(std::ceil(0.5 * blur.length_px)) + 1;
  cv::Mat1f kernel = cv::Mat1f::zeros(2 * half + 1, 2 * half + 1);
  const int samples = std::max(2, static_cast<int>(8 * blur.length_px));
  for (int k = 0; k < samples; ++k) {
    // Symmetric samples: t and -t both taken.
    const double t = blur.length_px * ((k + 0.5) / samples - 0.5);
    const double x = half + t * dx, y = half + t * dy;
    const int x0 = static_cast<int>(std::floor(x));
    const int y0 = static_cast<int>(std::floor(y));
    const double fx = x - x0, fy = y - y0;
    kernel(y0, x0) += static_cast<float>((1 - fx) * (1 - fy));
    kernel(y0, x0 + 1) += static_cast<float>(fx * (1 - fy));
    kernel(y0 + 1, x0) += static_cast<float>((1 - fx) * fy);
    kernel(y0 + 1, x0 + 1) += static_cast<float>(fx * fy);
  }
  kernel /= cv::sum(kernel)[0];
  return kernel;
}

// The 8-bit sensor image of the linear one: lighting gradient, vignetting,
// gamma and Gaussian noise. Each row draws its noise from its own stream,
// so the image is the same for any thread count.
cv::Mat1b ToSensorImage(const cv::Mat1f& linear, const RenderOptions& options) {
  const int width = linear.cols, height = linear.rows;
  cv::Mat1b image(height, width);
  const double contrast = options.white_level - options.black_level;
  const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
  const double r2_max = std::max(cx * cx + cy * cy, 1e-12);
  const double inv_gamma = 1.0 / options.gamma;
  const double x_span = std::max(width - 1, 1);
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& range) {
    for (int y = range.start; y < range.end; ++y) {
      // Independent streams per row: hash (seed, row) into the state (a
      // plain offset would make neighbouring rows shifted copies).
      uint64_t row_key = static_cast<uint64_t>(y);
      uint64_t rng = options.seed ^ SplitMix64(&row_key);
      SplitMix64(&rng);
      const float* in = linear.ptr<float>(y);
      uint8_t* out = image.ptr<uint8_t>(y);
      double spare_normal = 0.0;
      bool has_spare = false;
      for (int x = 0; x < width; ++x) {
        double v = in[x];
        v *= 1.0 + options.lighting_gradient * (x / x_span - 0.5);
        const double dx = x - cx, dy = y - cy;
        v *= 1.0 - options.vignetting * (dx * dx + dy * dy) / r2_max;
        v = std::clamp(v, 0.0, 1.0);
        if (inv_gamma != 1.0) v = std::pow(v, inv_gamma);
        if (options.noise_sigma > 0) {
          double normal;
          if (has_spare) {
            normal = spare_normal;
            has_spare = false;
          } else {
            // Box-Muller: two normals from two uniforms.
            const double radius = std::sqrt(-2.0 * std::log(Uniform(&rng)));
            const double angle = 2.0 * M_PI * Uniform(&rng);
            normal = radius * std::cos(angle);
            spare_normal = radius * std::sin(angle);
            has_spare = true;
          }
          v += options.noise_sigma * contrast * normal;
        }
        out[x] =
            static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
      }
    }
  });
  return image;
}

}  // namespace

cv::Mat RenderBoard(const Board& board, const PixelRayGrid& rays,
                    const Eigen::Isometry3d& cam_from_board,
                    const RenderOptions& options, RenderTruth* truth,
                    RenderSummary* summary) {
  RenderSummary local_summary;
  if (summary == nullptr) summary = &local_summary;
  *summary = RenderSummary();
  std::string why;
  if (!options.Check(&why)) return Fail(summary, "render options: " + why);
  if (!board.Check(&why)) return Fail(summary, "board: " + why);
  if (rays.empty()) {
    return Fail(summary, "pixel rays were not computed (unusable camera)");
  }
  if (!PoseIsValid(cam_from_board, &why)) return Fail(summary, why);

  const Camera& camera = rays.camera();
  const int width = camera.width, height = camera.height;
  const BoardShader shader(board, rays, cam_from_board, options);
  cv::Mat1f linear(height, width);
  std::vector<int> no_ray_per_row(height, 0), on_board_per_row(height, 0);
  // Rows are independent: the same image for any thread count.
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& range) {
    std::vector<const Occluder*> row_occluders;
    row_occluders.reserve(options.occluders.size());
    for (int y = range.start; y < range.end; ++y) {
      row_occluders.clear();
      for (const Occluder& o : options.occluders) {
        if (std::abs(o.center_px.y() - y) <= o.radius_px + 0.5) {
          row_occluders.push_back(&o);
        }
      }
      float* out = linear.ptr<float>(y);
      for (int x = 0; x < width; ++x) {
        bool on_board = false, has_ray = true;
        out[x] = shader.Shade(x, y, row_occluders, &on_board, &has_ray);
        on_board_per_row[y] += on_board ? 1 : 0;
        no_ray_per_row[y] += has_ray ? 0 : 1;
      }
    }
  });
  if (options.field_of_view_deg > 0) {
    ApplyImageCircle(rays, options.field_of_view_deg, &linear);
  }
  if (options.blur_sigma_px > 0) {
    cv::GaussianBlur(linear, linear, cv::Size(0, 0), options.blur_sigma_px,
                     options.blur_sigma_px, cv::BORDER_REPLICATE);
  }
  if (options.motion_blur.length_px > 0) {
    cv::filter2D(linear, linear, -1, MotionKernel(options.motion_blur),
                 cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
  }
  cv::Mat1b image = ToSensorImage(linear, options);

  summary->ok = true;
  for (int y = 0; y < height; ++y) {
    summary->num_pixels_without_ray += no_ray_per_row[y];
    summary->num_pixels_on_board += on_board_per_row[y];
  }
  std::vector<TruthCorner> corners =
      ProjectBoardCorners(board, camera, cam_from_board, options);
  for (const TruthCorner& c : corners) {
    summary->num_visible_corners += c.visible ? 1 : 0;
  }
  if (truth != nullptr) {
    truth->camera = camera;
    truth->cam_from_board = cam_from_board;
    truth->corners = std::move(corners);
  }
  return image;
}

}  // namespace puzzlecal
