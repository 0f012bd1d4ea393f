#include "decode/edge_bits.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "util/failure.h"

namespace puzzlecal {
namespace {

// Labels beyond this magnitude are treated as corrupt (keeps label arithmetic
// far from integer overflow).
constexpr int kMaxAbsLabel = 1 << 24;

// Bilinear sample of a one-channel image, normalised to [0, 1]. Returns false
// outside the image.
class Sampler {
 public:
  explicit Sampler(const cv::Mat& image) : image_(image) {
    switch (image.depth()) {
      case CV_8U:
        scale_ = 1.0 / 255.0;
        break;
      case CV_16U:
        scale_ = 1.0 / 65535.0;
        break;
      default:
        scale_ = 1.0;
    }
  }

  bool Sample(const Eigen::Vector2d& p, double* value) const {
    const double x = p.x(), y = p.y();
    if (!(x >= 0.0 && y >= 0.0 && x <= image_.cols - 1 &&
          y <= image_.rows - 1)) {
      return false;
    }
    const int x0 = std::min(static_cast<int>(x),
                            image_.cols - 2 < 0 ? 0 : image_.cols - 2);
    const int y0 = std::min(static_cast<int>(y),
                            image_.rows - 2 < 0 ? 0 : image_.rows - 2);
    const int x1 = std::min(x0 + 1, image_.cols - 1);
    const int y1 = std::min(y0 + 1, image_.rows - 1);
    const double fx = x - x0, fy = y - y0;
    const double v00 = At(x0, y0), v10 = At(x1, y0), v01 = At(x0, y1),
                 v11 = At(x1, y1);
    *value = scale_ * ((1 - fy) * ((1 - fx) * v00 + fx * v10) +
                       fy * ((1 - fx) * v01 + fx * v11));
    return true;
  }

 private:
  double At(int x, int y) const {
    switch (image_.depth()) {
      case CV_8U:
        return image_.at<unsigned char>(y, x);
      case CV_16U:
        return image_.at<unsigned short>(y, x);
      case CV_32F:
        return image_.at<float>(y, x);
      default:
        return image_.at<double>(y, x);
    }
  }

  const cv::Mat& image_;
  double scale_ = 1.0;
};

// Mean of the samples at p and p +- offset * u, p +- offset * v.
bool SampleStencil(const Sampler& sampler, const Eigen::Vector2d& p,
                   const Eigen::Vector2d& u, const Eigen::Vector2d& v,
                   double offset, double* mean) {
  const Eigen::Vector2d points[5] = {p, p + offset * u, p - offset * u,
                                     p + offset * v, p - offset * v};
  double sum = 0.0;
  for (const Eigen::Vector2d& q : points) {
    double s;
    if (!sampler.Sample(q, &s)) return false;
    sum += s;
  }
  *mean = sum / 5.0;
  return true;
}

}  // namespace

bool BuildLabelLattice(const std::vector<Corner>& corners,
                       const GridComponent& component, int max_extent,
                       LabelLattice* lattice, std::string* why) {
  *lattice = LabelLattice();
  const size_t n = std::min(component.corner.size(), component.ij.size());
  std::vector<int> valid;
  valid.reserve(n);
  Eigen::Vector2i lo(std::numeric_limits<int>::max(),
                     std::numeric_limits<int>::max());
  Eigen::Vector2i hi(std::numeric_limits<int>::min(),
                     std::numeric_limits<int>::min());
  for (size_t k = 0; k < n; ++k) {
    const int index = component.corner[k];
    const Eigen::Vector2i& ij = component.ij[k];
    if (index < 0 || index >= static_cast<int>(corners.size()) ||
        !corners[index].xy.allFinite() || std::abs(ij.x()) > kMaxAbsLabel ||
        std::abs(ij.y()) > kMaxAbsLabel) {
      ++lattice->dropped_invalid;
      continue;
    }
    valid.push_back(static_cast<int>(k));
    lo = lo.cwiseMin(component.ij[k]);
    hi = hi.cwiseMax(component.ij[k]);
  }
  lattice->dropped_invalid += static_cast<int>(
      std::max(component.corner.size(), component.ij.size()) - n);
  if (valid.empty()) {
    *why = "component has no corner with a valid index and finite position";
    return false;
  }
  const int64_t width = static_cast<int64_t>(hi.x()) - lo.x() + 1;
  const int64_t height = static_cast<int64_t>(hi.y()) - lo.y() + 1;
  if (width > max_extent || height > max_extent) {
    *why = "label extent " + std::to_string(width) + " x " +
           std::to_string(height) + " exceeds max_label_extent";
    return false;
  }
  lattice->min_label = lo;
  lattice->width = static_cast<int>(width);
  lattice->height = static_cast<int>(height);
  lattice->cell.assign(static_cast<size_t>(width * height), -1);
  // First pass: count occupants per cell to find duplicates.
  std::vector<int> count(lattice->cell.size(), 0);
  auto cell_of = [&](const Eigen::Vector2i& ij) {
    return (ij.x() - lo.x()) + lattice->width * (ij.y() - lo.y());
  };
  for (int k : valid) ++count[cell_of(component.ij[k])];
  for (int k : valid) {
    const int c = cell_of(component.ij[k]);
    if (count[c] > 1) {
      ++lattice->dropped_duplicates;
      continue;
    }
    lattice->cell[c] = static_cast<int>(lattice->xy.size());
    lattice->xy.push_back(corners[component.corner[k]].xy);
    lattice->label.push_back(component.ij[k]);
    lattice->corner_index.push_back(component.corner[k]);
  }
  if (lattice->xy.empty()) {
    *why = "every label of the component is held by more than one corner";
    return false;
  }
  return true;
}

std::vector<int> LatticeOutliers(const LabelLattice& lattice,
                                 double max_deviation) {
  std::vector<int> outliers;
  for (size_t k = 0; k < lattice.xy.size(); ++k) {
    const Eigen::Vector2i a = lattice.label[k];
    const Eigen::Vector2d& p = lattice.xy[k];
    int good = 0, bad = 0;
    for (int axis = 0; axis < 2; ++axis) {
      const Eigen::Vector2i e =
          axis == 0 ? Eigen::Vector2i(1, 0) : Eigen::Vector2i(0, 1);
      const int prev = lattice.At(a - e), next = lattice.At(a + e);
      const int prev2 = lattice.At(a - 2 * e), next2 = lattice.At(a + 2 * e);
      Eigen::Vector2d predicted;
      double step;
      if (prev >= 0 && next >= 0) {
        predicted = 0.5 * (lattice.xy[prev] + lattice.xy[next]);
        step = 0.5 * (lattice.xy[next] - lattice.xy[prev]).norm();
      } else if (prev >= 0 && prev2 >= 0) {
        predicted = 2.0 * lattice.xy[prev] - lattice.xy[prev2];
        step = (lattice.xy[prev] - lattice.xy[prev2]).norm();
      } else if (next >= 0 && next2 >= 0) {
        predicted = 2.0 * lattice.xy[next] - lattice.xy[next2];
        step = (lattice.xy[next] - lattice.xy[next2]).norm();
      } else {
        continue;
      }
      if ((p - predicted).norm() > max_deviation * step) {
        ++bad;
      } else {
        ++good;
      }
    }
    if (bad > good) outliers.push_back(static_cast<int>(k));
  }
  return outliers;
}

int LabelHandedness(const LabelLattice& lattice) {
  int positive = 0, negative = 0;
  for (size_t k = 0; k < lattice.xy.size(); ++k) {
    const Eigen::Vector2i& ij = lattice.label[k];
    const int right = lattice.At(ij.x() + 1, ij.y());
    const int down = lattice.At(ij.x(), ij.y() + 1);
    if (right < 0 || down < 0) continue;
    const Eigen::Vector2d a = lattice.xy[right] - lattice.xy[k];
    const Eigen::Vector2d b = lattice.xy[down] - lattice.xy[k];
    const double cross = a.x() * b.y() - a.y() * b.x();
    if (cross > 0) ++positive;
    if (cross < 0) ++negative;
  }
  if (positive > negative) return 1;
  if (negative > positive) return -1;
  return 0;
}

bool EdgeBitOptions::Check(std::string* why) const {
  if (!(min_confidence > 0.0 && min_confidence <= 1.0)) {
    return Fail("bits.min_confidence must be in (0, 1]", why);
  }
  if (!(min_tile_contrast >= 0.0 && min_tile_contrast < 1.0)) {
    return Fail("bits.min_tile_contrast must be in [0, 1)", why);
  }
  if (!(disc_sample_offset >= 0.0 && disc_sample_offset <= 1.0 / 6.0)) {
    return Fail("bits.disc_sample_offset must be in [0, 1/6]", why);
  }
  if (!(tile_sample_offset >= 0.0 && tile_sample_offset <= 0.3)) {
    return Fail("bits.tile_sample_offset must be in [0, 0.3]", why);
  }
  return true;
}

namespace {

// The image position of label ij, or null when it holds no corner.
const Eigen::Vector2d* PointAt(const LabelLattice& lattice,
                               const Eigen::Vector2i& ij) {
  const int k = lattice.At(ij);
  return k < 0 ? nullptr : &lattice.xy[k];
}

// Where the tiles, the edge and its disc are sampled for the lattice edge
// a -> b = a + e (f: the other axis).
struct EdgeGeometry {
  Eigen::Vector2d mid;        // edge midpoint (the disc's centre)
  Eigen::Vector2d along;      // the edge vector a -> b
  Eigen::Vector2d across;     // one lattice step along f
  Eigen::Vector2d centre[2];  // tile centres, [0]: side +f, [1]: side -f
};

EdgeGeometry EdgeSamplePoints(const LabelLattice& lattice,
                              const Eigen::Vector2i& a,
                              const Eigen::Vector2i& e,
                              const Eigen::Vector2i& f,
                              const Eigen::Vector2d& pa,
                              const Eigen::Vector2d& pb) {
  const Eigen::Vector2i b = a + e;
  EdgeGeometry g;
  // Edge midpoint by Lagrange interpolation at t = 1/2 through the corners
  // at t = -1, 0, 1, 2 along the lattice line.
  const Eigen::Vector2d* before = PointAt(lattice, a - e);
  const Eigen::Vector2d* after = PointAt(lattice, b + e);
  if (before != nullptr && after != nullptr) {
    g.mid = (9.0 * (pa + pb) - *before - *after) / 16.0;
  } else if (before != nullptr) {
    g.mid = -0.125 * *before + 0.75 * pa + 0.375 * pb;
  } else if (after != nullptr) {
    g.mid = 0.375 * pa + 0.75 * pb - 0.125 * *after;
  } else {
    g.mid = 0.5 * (pa + pb);
  }
  g.along = pb - pa;
  // Tile centres on both sides: the mean of the tile's four corners when
  // all are labelled, else half a lattice step across from the midpoint.
  g.across = Eigen::Vector2d(-g.along.y(), g.along.x());
  if (const Eigen::Vector2d* q = PointAt(lattice, Eigen::Vector2i(a + f))) {
    g.across = *q - pa;
  } else if (const Eigen::Vector2d* q =
                 PointAt(lattice, Eigen::Vector2i(b + f))) {
    g.across = *q - pb;
  } else if (const Eigen::Vector2d* q =
                 PointAt(lattice, Eigen::Vector2i(a - f))) {
    g.across = pa - *q;
  } else if (const Eigen::Vector2d* q =
                 PointAt(lattice, Eigen::Vector2i(b - f))) {
    g.across = pb - *q;
  }
  for (int side = 0; side < 2; ++side) {
    const Eigen::Vector2i s = side == 0 ? f : Eigen::Vector2i(-f);
    const Eigen::Vector2d* qa = PointAt(lattice, a + s);
    const Eigen::Vector2d* qb = PointAt(lattice, b + s);
    if (qa != nullptr && qb != nullptr) {
      g.centre[side] = 0.25 * (pa + pb + *qa + *qb);
    } else {
      g.centre[side] = g.mid + (side == 0 ? 0.5 : -0.5) * g.across;
    }
  }
  return g;
}

// Samples the two tiles and the disc of one edge: fills edge->confidence and
// edge->read; `dark_side` gets 0 when the tile on side +f is the darker one,
// 1 when the one on side -f is, -1 when the tiles could not be compared.
void SampleEdge(const Sampler& sampler, const EdgeGeometry& g,
                const EdgeBitOptions& options, EdgeBit* edge, int* dark_side) {
  *dark_side = -1;
  double level[2] = {0.0, 0.0};
  bool ok = SampleStencil(sampler, g.centre[0], g.along, g.across,
                          options.tile_sample_offset, &level[0]) &&
            SampleStencil(sampler, g.centre[1], g.along, g.across,
                          options.tile_sample_offset, &level[1]);
  double disc = 0.0;
  if (ok) {
    const double o = options.disc_sample_offset;
    double s0 = 0.0, s1 = 0.0, s2 = 0.0;
    ok = sampler.Sample(g.mid, &s0) &&
         sampler.Sample(g.mid + o * g.along, &s1) &&
         sampler.Sample(g.mid - o * g.along, &s2);
    disc = (s0 + s1 + s2) / 3.0;
  }
  const double contrast = std::abs(level[0] - level[1]);
  if (ok && contrast >= options.min_tile_contrast && contrast > 0.0) {
    const double mid_level = 0.5 * (level[0] + level[1]);
    edge->confidence =
        std::clamp((disc - mid_level) / (0.5 * contrast), -1.0, 1.0);
    edge->read = std::abs(edge->confidence) >= options.min_confidence;
    *dark_side = level[0] < level[1] ? 0 : 1;
  }
}

}  // namespace

EdgeBitReading ReadEdgeBits(const LabelLattice& lattice, const cv::Mat& image,
                            const EdgeBitOptions& options) {
  EdgeBitReading reading;
  if (image.empty() || image.channels() != 1) return reading;
  const Sampler sampler(image);
  int parity_votes[2] = {0, 0};
  reading.edges.reserve(2 * lattice.xy.size());
  for (size_t k = 0; k < lattice.xy.size(); ++k) {
    const Eigen::Vector2i a = lattice.label[k];
    for (int axis = 0; axis < 2; ++axis) {
      const Eigen::Vector2i e =
          axis == 0 ? Eigen::Vector2i(1, 0) : Eigen::Vector2i(0, 1);
      const Eigen::Vector2i f =
          axis == 0 ? Eigen::Vector2i(0, 1) : Eigen::Vector2i(1, 0);
      const Eigen::Vector2d* pb = PointAt(lattice, a + e);
      if (pb == nullptr) continue;
      EdgeBit edge;
      edge.from = a;
      edge.axis = axis;
      const EdgeGeometry g =
          EdgeSamplePoints(lattice, a, e, f, lattice.xy[k], *pb);
      int dark_side;
      SampleEdge(sampler, g, options, &edge, &dark_side);
      if (dark_side >= 0) {
        // The tile on side +f has min corner a (axis 0: tile (i, j); axis 1:
        // tile (i, j)) and the one on side -f has min corner a - f.
        const Eigen::Vector2i dark_tile =
            dark_side == 0 ? a : Eigen::Vector2i(a - f);
        ++parity_votes[(dark_tile.x() + dark_tile.y()) & 1];
      }
      if (edge.read) ++reading.num_read;
      reading.edges.push_back(edge);
    }
  }
  reading.parity_votes_total = parity_votes[0] + parity_votes[1];
  if (parity_votes[0] != parity_votes[1]) {
    reading.dark_tile_parity = parity_votes[0] > parity_votes[1] ? 0 : 1;
    reading.dark_parity_votes = std::max(parity_votes[0], parity_votes[1]);
  }
  return reading;
}

}  // namespace puzzlecal
