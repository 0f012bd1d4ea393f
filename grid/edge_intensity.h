#ifndef PUZZLECAL_GRID_EDGE_INTENSITY_H_
#define PUZZLECAL_GRID_EDGE_INTENSITY_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace puzzlecal {

// True for the image types the intensity penalty reads: CV_8UC1, CV_16UC1,
// CV_32FC1 (non-empty).
bool IsSupportedGridImage(const cv::Mat& image);

// The thesis's test for an edge that crosses a tile: `num_samples` grey
// levels (bilinear, clamped to the image) at (s + 0.5) / num_samples of the
// way from a to b; true when the mean of the first third and the mean of the
// last third differ by more than `fraction` times the mean of all samples.
// image: a supported type. No allocation.
bool EdgeCrossesTile(const cv::Mat& image, const Eigen::Vector2d& a,
                     const Eigen::Vector2d& b, int num_samples,
                     double fraction);

// True when the edge from a to b runs along two tile edges instead of one: it
// passes through a corner that was not detected, so the tiles beside it
// change colour halfway. Samples on both sides of the edge (offset
// `offset_fraction` of its length perpendicular to it) at 1/4 and 3/4 of the
// way: the left-minus-right grey difference changes sign between the two
// places, and both differences exceed `min_contrast` times the mean of the
// four samples. image: a supported type. No allocation.
bool EdgeSidesFlip(const cv::Mat& image, const Eigen::Vector2d& a,
                   const Eigen::Vector2d& b, double offset_fraction,
                   double min_contrast);

}  // namespace puzzlecal

#endif  // PUZZLECAL_GRID_EDGE_INTENSITY_H_
