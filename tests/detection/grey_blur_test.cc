#include "detection/grey_blur.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <vector>

namespace puzzlecal {
namespace {

// cv::sepFilter2D of the same rows (a band of a larger image reads the
// image's rows around it, replicated at the image border).
cv::Mat OpenCvRows(const cv::Mat& image, int first, int last,
                   const cv::Mat& kernel_x, const cv::Mat& kernel_y) {
  cv::Mat out;
  cv::sepFilter2D(image.rowRange(first, last), out, CV_32F, kernel_x, kernel_y,
                  cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  return out;
}

TEST(GreyBlurTest, EqualsOpenCvsSeparableFilterOnBandsAndBorders) {
  const cv::Mat kernel_y = cv::getGaussianKernel(5, 1.0, CV_32F);
  const cv::Mat kernel_x = kernel_y * (1.0 / 251.0);  // normalisation folded
  // Widths below one vector, between, and not a multiple of 8 or 16.
  for (const cv::Size size :
       {cv::Size(3, 4), cv::Size(13, 9), cv::Size(37, 23), cv::Size(203, 71)}) {
    cv::Mat image(size, CV_8UC1);
    cv::RNG rng(size.width);
    rng.fill(image, cv::RNG::UNIFORM, 0, 256);
    std::vector<float> row;
    const int h = size.height;
    for (const cv::Range rows :
         {cv::Range(0, h), cv::Range(0, 1), cv::Range(h - 1, h),
          cv::Range(1, h - 1), cv::Range(h / 2, h / 2 + 1)}) {
      cv::Mat out(rows.size(), size.width, CV_32FC1, cv::Scalar(-1));
      BlurGreyRows5(image, rows.start, rows.end, kernel_x, kernel_y, &row,
                    &out);
      const cv::Mat expected =
          OpenCvRows(image, rows.start, rows.end, kernel_x, kernel_y);
      // The same sums in another order: a float rounding or two apart.
      EXPECT_LE(cv::norm(out, expected, cv::NORM_INF), 4e-7)
          << size << " rows " << rows.start << ".." << rows.end;
    }
  }
}

TEST(GreyBlurTest, ConstantImageStaysConstant) {
  const cv::Mat kernel = cv::getGaussianKernel(5, 1.0, CV_32F);
  const cv::Mat image(17, 29, CV_8UC1, cv::Scalar(200));
  cv::Mat out(17, 29, CV_32FC1);
  std::vector<float> row;
  BlurGreyRows5(image, 0, 17, kernel, kernel, &row, &out);
  double lo, hi;
  cv::minMaxLoc(out, &lo, &hi);
  EXPECT_NEAR(lo, 200.0, 1e-4);
  EXPECT_NEAR(hi, 200.0, 1e-4);
}

TEST(GreyBlurTest, OnlySymmetricFiveTapFloatKernelsAreTaken) {
  EXPECT_TRUE(IsSymmetricKernel5(cv::getGaussianKernel(5, 1.0, CV_32F)));
  EXPECT_TRUE(IsSymmetricKernel5(cv::getGaussianKernel(5, 0.7, CV_32F)));
  EXPECT_FALSE(IsSymmetricKernel5(cv::getGaussianKernel(7, 1.5, CV_32F)));
  EXPECT_FALSE(IsSymmetricKernel5(cv::getGaussianKernel(5, 1.0, CV_64F)));
  cv::Mat skewed = cv::getGaussianKernel(5, 1.0, CV_32F);
  skewed.at<float>(0) += 0.01f;
  EXPECT_FALSE(IsSymmetricKernel5(skewed));
}

}  // namespace
}  // namespace puzzlecal
