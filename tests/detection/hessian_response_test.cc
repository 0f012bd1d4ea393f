#include "detection/hessian_response.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "sim/scenes.h"

namespace puzzlecal {
namespace {

// The definition of FindSaddlePeaks, pixel by pixel on the stored
// response: above the threshold, and in its clipped (2 radius + 1)^2
// window larger than every pixel before it in scan order and not smaller
// than any after it.
std::vector<ResponsePeak> ReferencePeaks(const cv::Mat& response,
                                         float threshold, int radius,
                                         int* above) {
  std::vector<ResponsePeak> peaks;
  *above = 0;
  for (int y = 1; y < response.rows - 1; ++y) {
    for (int x = 1; x < response.cols - 1; ++x) {
      const float v = response.at<float>(y, x);
      if (!(v > threshold)) continue;
      ++*above;
      bool is_peak = true;
      for (int yy = std::max(y - radius, 0);
           is_peak && yy <= std::min(y + radius, response.rows - 1); ++yy) {
        for (int xx = std::max(x - radius, 0);
             xx <= std::min(x + radius, response.cols - 1); ++xx) {
          const bool earlier = yy < y || (yy == y && xx < x);
          const float w = response.at<float>(yy, xx);
          if (earlier ? w >= v : w > v) {
            is_peak = false;
            break;
          }
        }
      }
      if (is_peak) {
        ResponsePeak peak;
        peak.x = x;
        peak.y = y;
        peak.value = v;
        peaks.push_back(peak);
      }
    }
  }
  return peaks;
}

cv::Mat Blurred(const cv::Mat& grey) {
  cv::Mat blurred;
  grey.convertTo(blurred, CV_32F, 1.0 / 255.0);
  cv::GaussianBlur(blurred, blurred, cv::Size(5, 5), 1.0);
  return blurred;
}

// Board renders (corners, edges, discs) and pure noise (peaks everywhere),
// plus a quantised copy of the noise whose response has ties.
std::vector<cv::Mat> TestImages() {
  std::vector<cv::Mat> images;
  std::string why;
  const std::vector<SceneView> views =
      RenderScene(StrongFisheyeScene(320, 240), &why);
  EXPECT_FALSE(views.empty()) << why;
  for (size_t i = 0; i < views.size() && i < 2; ++i) {
    images.push_back(Blurred(views[i].image));
  }
  cv::Mat noise(97, 131, CV_8UC1);  // widths not a multiple of 8 or 64
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  images.push_back(Blurred(noise));
  cv::Mat coarse = noise / 64 * 64;
  cv::Mat flat;
  coarse.convertTo(flat, CV_32F, 1.0 / 255.0);  // no blur: equal responses
  images.push_back(flat);
  return images;
}

void ExpectSamePeaks(const std::vector<ResponsePeak>& found,
                     const std::vector<ResponsePeak>& expected,
                     const std::string& what) {
  ASSERT_EQ(found.size(), expected.size()) << what;
  for (size_t i = 0; i < found.size(); ++i) {
    EXPECT_EQ(found[i].x, expected[i].x) << what << " peak " << i;
    EXPECT_EQ(found[i].y, expected[i].y) << what << " peak " << i;
    EXPECT_EQ(found[i].value, expected[i].value) << what << " peak " << i;
  }
}

TEST(HessianResponseTest, PeaksAreThoseOfTheDefinition) {
  const float k = 0.5f;
  int image_index = 0;
  for (const cv::Mat& blurred : TestImages()) {
    cv::Mat response;
    ComputeSaddleResponse(blurred, k, &response);
    // The median of the positive responses and far below it: few and many
    // pixels above the threshold.
    std::vector<float> positive;
    for (int y = 0; y < response.rows; ++y) {
      for (int x = 0; x < response.cols; ++x) {
        if (response.at<float>(y, x) > 0) {
          positive.push_back(response.at<float>(y, x));
        }
      }
    }
    ASSERT_FALSE(positive.empty());
    std::nth_element(positive.begin(), positive.begin() + positive.size() / 2,
                     positive.end());
    const float median = positive[positive.size() / 2];
    for (float threshold : {median, 1e-3f * median}) {
      for (int radius : {1, 2, 3}) {
        const std::string what = "image " + std::to_string(image_index) +
                                 " threshold " + std::to_string(threshold) +
                                 " radius " + std::to_string(radius);
        int expected_above = 0;
        const std::vector<ResponsePeak> expected =
            ReferencePeaks(response, threshold, radius, &expected_above);
        std::vector<float> rows;
        std::vector<ResponsePeak> found;
        const int above =
            FindSaddlePeaks(blurred, k, threshold, radius, &rows, &found);
        EXPECT_EQ(above, expected_above) << what;
        ExpectSamePeaks(found, expected, what);
      }
    }
    ++image_index;
  }
}

// Bands of rows (with the rows around them) find the whole image's peaks.
TEST(HessianResponseTest, BandsOfRowsFindTheWholeImagesPeaks) {
  const float k = 0.5f;
  const int radius = 2, halo = 2 + radius;
  for (const cv::Mat& blurred : TestImages()) {
    std::vector<float> rows;
    std::vector<ResponsePeak> whole;
    const float threshold = 1e-6f;
    const int whole_above =
        FindSaddlePeaks(blurred, k, threshold, radius, &rows, &whole);
    std::vector<ResponsePeak> banded;
    int banded_above = 0;
    for (int y0 = 0; y0 < blurred.rows; y0 += 16) {
      const int y1 = std::min(y0 + 16, blurred.rows);
      const int a = std::max(0, y0 - halo);
      const int b = std::min(blurred.rows, y1 + halo);
      PeakRows part;
      part.begin = y0 - a;
      part.end = y1 - a;
      part.y_offset = a;
      std::vector<ResponsePeak> peaks;
      banded_above += FindSaddlePeaksInRows(
          blurred.rowRange(a, b), k, threshold, radius, part, &rows, &peaks);
      for (ResponsePeak peak : peaks) {
        peak.y += a;
        peak.centroid_y += a;
        banded.push_back(peak);
      }
    }
    EXPECT_EQ(banded_above, whole_above);
    ExpectSamePeaks(banded, whole, "bands");
  }
}

}  // namespace
}  // namespace puzzlecal
