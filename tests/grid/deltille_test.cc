// DetectCorners + BuildGrid on the deltille fisheye photos (an 11 x 8 inner
// corner checkerboard, strong fisheye). Without per-corner truth, a component
// counts as wrong when its labels cannot be a piece of that board seen by a
// camera:
// - its labels do not fit in an 11 x 8 (or 8 x 11) box, or
// - a lattice cell (labels L, L + i, L + i + j, L + j all present) is not a
//   convex quadrilateral in the image, or two cells of the component have
//   opposite handedness (a camera shows one side of the board: a mirrored or
//   rotated part flips or twists cells), or
// - two lattice neighbours are more than 3 times farther apart than the
//   median neighbour distance at either of them.
// Prints the per-photo table.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "detection/detector.h"
#include "grid/grid.h"
#include "tests/support/deltille_data.h"
#include "tests/support/shared_data.h"

namespace puzzlecal {
namespace {

struct ComponentVerdict {
  bool fits_box = true;
  bool cells_ok = true;
  bool spacing_ok = true;
  bool ok() const { return fits_box && cells_ok && spacing_ok; }
};

ComponentVerdict JudgeComponent(const GridComponent& component,
                                const std::vector<Corner>& corners) {
  ComponentVerdict verdict;
  std::map<std::pair<int, int>, Eigen::Vector2d> at;
  Eigen::Vector2i high(0, 0);
  for (size_t k = 0; k < component.corner.size(); ++k) {
    at[{component.ij[k].x(), component.ij[k].y()}] =
        corners[component.corner[k]].xy;
    high = high.cwiseMax(component.ij[k]);
  }
  const int span_i = high.x() + 1, span_j = high.y() + 1;
  verdict.fits_box =
      (span_i <= 11 && span_j <= 8) || (span_i <= 8 && span_j <= 11);
  int handedness = 0;
  for (const auto& [label, p0] : at) {
    const auto p1 = at.find({label.first + 1, label.second});
    const auto p2 = at.find({label.first + 1, label.second + 1});
    const auto p3 = at.find({label.first, label.second + 1});
    if (p1 == at.end() || p2 == at.end() || p3 == at.end()) continue;
    const Eigen::Vector2d q[4] = {p0, p1->second, p2->second, p3->second};
    int sign = 0;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d e1 = q[(k + 1) % 4] - q[k];
      const Eigen::Vector2d e2 = q[(k + 2) % 4] - q[(k + 1) % 4];
      const double cross = e1.x() * e2.y() - e1.y() * e2.x();
      const int s = cross > 0 ? 1 : -1;
      if (sign == 0) sign = s;
      if (s != sign) verdict.cells_ok = false;
    }
    if (handedness == 0) handedness = sign;
    if (sign != handedness) verdict.cells_ok = false;
  }
  // Neighbour distances against the median at each corner.
  auto neighbour_distances = [&](const std::pair<int, int>& label) {
    std::vector<double> d;
    const Eigen::Vector2d& p = at.at(label);
    const int steps[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
    for (const auto& s : steps) {
      const auto q = at.find({label.first + s[0], label.second + s[1]});
      if (q != at.end()) d.push_back((q->second - p).norm());
    }
    return d;
  };
  for (const auto& [label, p] : at) {
    std::vector<double> d = neighbour_distances(label);
    if (d.size() < 2) continue;
    std::sort(d.begin(), d.end());
    const double median = d[d.size() / 2];
    if (d.back() > 3 * median && d.front() * 3 < median)
      verdict.spacing_ok = false;
  }
  return verdict;
}

TEST(DeltilleTest, FisheyePhotosHaveConsistentComponents) {
  const std::vector<std::string> files =
      testing_data::DeltillePhotoFiles(testing_data::DeltilleFolder());
  if (files.empty()) {
    PUZZLECAL_SKIP_WITHOUT_DATA(
        "no deltille photos: " << testing_data::DeltilleHowToGet());
  }
  int photos = 0, wrong_components = 0, all_88 = 0, photos_with_88 = 0;
  std::printf("photo  corners  components  largest  span    verdict\n");
  for (const std::string& file : files) {
    const cv::Mat image = cv::imread(file, cv::IMREAD_GRAYSCALE);
    const std::vector<Corner> corners = DetectCorners(image);
    GridSummary summary;
    const std::vector<GridComponent> components =
        BuildGrid(corners, image, {}, &summary);
    ASSERT_TRUE(summary.ok) << summary.message;
    ++photos;
    int bad = 0;
    for (const GridComponent& component : components) {
      const ComponentVerdict verdict = JudgeComponent(component, corners);
      if (!verdict.ok()) ++bad;
    }
    wrong_components += bad;
    Eigen::Vector2i span(0, 0);
    if (!components.empty()) {
      for (const Eigen::Vector2i& l : components[0].ij)
        span = span.cwiseMax(l + Eigen::Vector2i(1, 1));
    }
    const int largest = summary.largest_component;
    if (static_cast<int>(corners.size()) >= 88) ++photos_with_88;
    if (largest == 88) ++all_88;
    std::printf("%s  %7zu  %10d  %7d  %2dx%-2d  %s\n",
                file.substr(file.size() - 8, 4).c_str(), corners.size(),
                summary.num_components, largest, span.x(), span.y(),
                bad ? "WRONG" : "ok");
  }
  std::printf(
      "photos %d, components judged wrong %d, all 88 corners in one "
      "component on %d (photos with >= 88 detections: %d)\n",
      photos, wrong_components, all_88, photos_with_88);
  EXPECT_EQ(wrong_components, 0);
}

}  // namespace
}  // namespace puzzlecal
