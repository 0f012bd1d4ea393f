#include "report/report.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "camera/camera_models.h"
#include "sim/render.h"
#include "sim/synthetic_views.h"
#include "target/board.h"
#include "tests/support/files.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;
using testing_files::ReadFile;

// A fresh folder under the test temp dir.
fs::path FreshDir(const std::string& name) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("puzzlecal_report_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Removes a test's folder unless PUZZLECAL_KEEP_TEST_OUTPUT is set (to look
// at the plots).
void RemoveUnlessKept(const fs::path& dir) {
  if (std::getenv("PUZZLECAL_KEEP_TEST_OUTPUT") == nullptr) fs::remove_all(dir);
}

// A valid PNG: the signature, and OpenCV decodes it; returns its size.
cv::Size PngSize(const fs::path& path) {
  const std::string bytes = ReadFile(path);
  const std::string signature = "\x89PNG\r\n\x1a\n";
  EXPECT_EQ(bytes.substr(0, 8), signature) << path;
  const cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  EXPECT_FALSE(image.empty()) << path;
  EXPECT_EQ(image.type(), CV_8UC3) << path;
  return image.size();
}

// A chart that shows something: at least 2 % of its pixels are not white.
void ExpectNotBlank(const fs::path& path) {
  const cv::Mat image = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(image.empty()) << path;
  const int drawn = cv::countNonZero(image < 250);
  EXPECT_GT(drawn, 0.02 * image.total()) << path;
}

Board CheckerBoard(double tile) {
  Board board =
      MakeBoard(BoardType::kCheckerboard, 11, 8, Eigen::Vector2i::Zero(), tile);
  return board;
}

// Synthetic calibration with known truth, rendered view images on disk and
// the input of WriteReport, as `puzzlecal calibrate` would assemble it.
struct SyntheticRun {
  sim::SyntheticData data;
  Camera truth;
  CalibrationResult result;
  bool calibrated = false;
  std::string calibrate_error;
  ReportInput input;
};

void MakeRun(const sim::SyntheticScene& scene, const fs::path& image_dir,
             bool render, SyntheticRun* run) {
  run->truth = scene.camera;
  run->data = sim::MakeSyntheticData(scene);
  const Board board = CheckerBoard(scene.tile);
  run->input.board = board;
  // Two images that yielded nothing come first, as a folder listing would.
  ReportImage unreadable;
  unreadable.file = (image_dir / "a_broken.png").string();
  unreadable.outcome = ImageOutcome::kUnreadable;
  unreadable.reason = "not an image";
  run->input.images.push_back(unreadable);
  ReportImage empty;
  empty.file = (image_dir / "b_wall.png").string();
  empty.outcome = ImageOutcome::kNoCorners;
  empty.corners_detected = 3;
  run->input.images.push_back(empty);
  for (size_t v = 0; v < run->data.views.size(); ++v) {
    char name[32];
    std::snprintf(name, sizeof(name), "view_%02zu.png", v);
    const std::string file = (image_dir / name).string();
    run->data.views[v].name = file;
    if (render) {
      RenderOptions options;
      options.supersampling = 2;
      options.noise_sigma = 0.01;
      const cv::Mat image = RenderBoard(board, scene.camera,
                                        run->data.cam_from_board[v], options);
      ASSERT_FALSE(image.empty());
      ASSERT_TRUE(cv::imwrite(file, image));
    }
    ReportImage image;
    image.file = file;
    image.outcome = ImageOutcome::kUsable;
    image.use = ViewUse::kUsed;
    image.corners_detected =
        static_cast<int>(run->data.views[v].image_points.size());
    image.view_index = static_cast<int>(v);
    run->input.images.push_back(image);
  }
  CalibrationOptions options;
  run->calibrated = Calibrate(run->data.views, scene.camera.model,
                              scene.camera.width, scene.camera.height, options,
                              &run->result, &run->calibrate_error);
  run->input.result = &run->result;
  run->input.views = &run->data.views;
  run->input.calibration_ok = run->calibrated;
  run->input.calibration_error = run->calibrate_error;
  run->input.seconds_load = 0.5;
  run->input.seconds_detect = 1.25;
  run->input.seconds_calibrate = 0.75;
  run->input.seconds_total = 2.5;
  run->input.threads = 2;
}

// RFC 4648 base64, decoded independently of the writer's encoder.
std::string Base64Decode(const std::string& text) {
  const std::string alphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  int bits = 0;
  uint32_t buffer = 0;
  for (char c : text) {
    if (c == '=') break;
    const size_t value = alphabet.find(c);
    if (value == std::string::npos) return "";
    buffer = buffer << 6 | static_cast<uint32_t>(value);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((buffer >> bits) & 0xff);
    }
  }
  return out;
}

sim::SyntheticScene SmallRadtanScene() {
  sim::SyntheticScene scene;
  scene.camera = sim::MakeCamera(
      CameraModelId::kPinholeRadtan, 640, 480,
      {410.0, 409.3, 321.2, 238.6, -0.28, 0.09, 0.0006, -0.0004, -0.012});
  scene.num_views = 8;
  scene.noise_px = 0.15;
  scene.outlier_fraction = 0.01;
  scene.max_direction_deg = 30;
  scene.seed = 7;
  return scene;
}

// Parses the parameter table of summary.md: name -> (value, sigma text).
std::map<std::string, std::pair<std::string, std::string>> ParamTable(
    const std::string& markdown) {
  std::map<std::string, std::pair<std::string, std::string>> table;
  const std::regex row(
      R"(\| (\w+) \| (-?[0-9.e+-]+) \| ([0-9.a-z/]+) \| (px)? \|)");
  for (std::sregex_iterator it(markdown.begin(), markdown.end(), row), end;
       it != end; ++it) {
    table[(*it)[1]] = {(*it)[2], (*it)[3]};
  }
  return table;
}

// Number of decimals printed in `text`.
int Decimals(const std::string& text) {
  const size_t dot = text.find('.');
  return dot == std::string::npos ? 0 : static_cast<int>(text.size() - dot - 1);
}

TEST(ReportTest, WritesSummaryAndPlotsForARenderedRun) {
  const fs::path dir = FreshDir("radtan");
  const fs::path image_dir = dir / "images";
  fs::create_directories(image_dir);
  SyntheticRun run;
  MakeRun(SmallRadtanScene(), image_dir, /*render=*/true, &run);
  ASSERT_TRUE(run.calibrated) << run.calibrate_error;
  ASSERT_GT(run.result.num_outliers, 0) << "the scene should hold outliers";

  const ReportOptions options;
  std::string error;
  ReportSummary summary;
  const fs::path report_dir = dir / "report" / "nested";
  // The plotting library must not talk on the terminal.
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  const bool written =
      WriteReport(report_dir.string(), run.input, options, &error, &summary);
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "");
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  ASSERT_TRUE(written) << error;
  EXPECT_TRUE(summary.warnings.empty()) << summary.warnings.front();

  // Image-shaped plots keep the image's aspect ratio in their plot area.
  const std::vector<std::string> image_charts = {
      "residuals.png", "coverage.png", "distortion.png"};
  const std::vector<std::string> charts = {"residual_histogram.png",
                                           "view_rms.png"};
  for (const std::string& name : image_charts) {
    ASSERT_NE(std::find(summary.files.begin(), summary.files.end(), name),
              summary.files.end())
        << name;
    const cv::Size size = PngSize(report_dir / name);
    EXPECT_EQ(size.width, options.image_plot_width) << name;
    const double area_height = (options.image_plot_width - 230) * 480.0 / 640;
    EXPECT_GT(size.height, area_height) << name;
    EXPECT_LT(size.height, area_height + 300) << name;
    ExpectNotBlank(report_dir / name);
  }
  for (const std::string& name : charts) {
    ASSERT_NE(std::find(summary.files.begin(), summary.files.end(), name),
              summary.files.end())
        << name;
    EXPECT_EQ(PngSize(report_dir / name),
              cv::Size(options.chart_width, options.chart_height))
        << name;
    ExpectNotBlank(report_dir / name);
  }
  // The same input gives the same bytes (no time stamps, no state carried
  // over from the previous charts).
  const fs::path again = dir / "again";
  ASSERT_TRUE(WriteReport(again.string(), run.input, options, &error)) << error;
  for (const std::string& file : summary.files) {
    EXPECT_EQ(ReadFile(again / file), ReadFile(report_dir / file)) << file;
  }

  // Overlays: the worst view by RMS, the view with the most outliers, and
  // the best two views.
  std::vector<int> by_rms;
  for (size_t v = 0; v < run.result.view_rms_px.size(); ++v) {
    if (run.result.view_used[v]) by_rms.push_back(static_cast<int>(v));
  }
  std::sort(by_rms.begin(), by_rms.end(), [&](int a, int b) {
    return run.result.view_rms_px[a] > run.result.view_rms_px[b];
  });
  ASSERT_GE(by_rms.size(), 4u);
  int most_outliers = -1, max_outliers = 0;
  for (int v : by_rms) {
    const auto& inlier = run.result.inlier[v];
    const int outliers =
        static_cast<int>(std::count(inlier.begin(), inlier.end(), false));
    if (outliers > max_outliers) {
      max_outliers = outliers;
      most_outliers = v;
    }
  }
  ASSERT_GE(most_outliers, 0);
  ASSERT_NE(most_outliers, by_rms[0]) << "pick a scene where they differ";
  const std::vector<int> expected_overlays = {
      by_rms[0], most_outliers, by_rms.end()[-1], by_rms.end()[-2]};
  int overlays = 0;
  for (const std::string& file : summary.files) {
    if (file.rfind("overlay_", 0) == 0) ++overlays;
  }
  EXPECT_EQ(overlays, options.num_overlays);
  for (int v : expected_overlays) {
    char name[32];
    std::snprintf(name, sizeof(name), "overlay_view_%02d.png", v);
    ASSERT_TRUE(fs::exists(report_dir / name)) << name;
    // Scaled to overlay_width, the image's aspect kept, plus text bands.
    const cv::Size size = PngSize(report_dir / name);
    EXPECT_EQ(size.width, options.overlay_width) << name;
    const double image_height = options.overlay_width * 480.0 / 640;
    EXPECT_GT(size.height, image_height) << name;
    EXPECT_LT(size.height, image_height + 200) << name;
  }

  const std::string markdown = ReadFile(report_dir / "summary.md");
  ASSERT_FALSE(markdown.empty());
  EXPECT_NE(markdown.find("pinhole-radtan"), std::string::npos);
  EXPECT_NE(markdown.find("640 x 480"), std::string::npos);
  EXPECT_EQ(markdown.find("Calibration failed"), std::string::npos);
  // Every table's header row names its columns (a header row is the line
  // above a "|---" line).
  {
    std::istringstream lines(markdown);
    std::string previous, line;
    int tables = 0;
    while (std::getline(lines, line)) {
      if (line.rfind("|---", 0) == 0) {
        ++tables;
        EXPECT_EQ(previous.find("| |"), std::string::npos) << previous;
        EXPECT_EQ(previous.find("||"), std::string::npos) << previous;
      }
      previous = line;
    }
    EXPECT_GE(tables, 3);
  }

  // Every parameter, printed to the precision its sigma asks for, matches
  // the result to that precision and the truth within 5 sigma.
  const auto table = ParamTable(markdown);
  const std::vector<std::string> names =
      CameraModelParamNames(CameraModelId::kPinholeRadtan);
  ASSERT_TRUE(run.result.covariance_ok);
  for (size_t k = 0; k < names.size(); ++k) {
    ASSERT_TRUE(table.count(names[k])) << names[k] << "\n" << markdown;
    const auto& [value_text, sigma_text] = table.at(names[k]);
    const double value = std::atof(value_text.c_str());
    const double sigma = std::atof(sigma_text.c_str());
    const double half_digit = 0.5 * std::pow(10.0, -Decimals(value_text));
    EXPECT_LE(std::abs(value - run.result.camera.params[k]), half_digit * 1.001)
        << names[k] << " printed " << value_text;
    EXPECT_LE(std::abs(sigma - run.result.param_stddev[k]), half_digit * 1.001)
        << names[k] << " sigma printed " << sigma_text;
    // Three significant digits of sigma.
    EXPECT_GE(sigma, 100 * half_digit * 1.999) << names[k];
    EXPECT_LT(sigma, 1000 * half_digit * 2.001) << names[k];
    EXPECT_LE(std::abs(value - run.truth.params[k]), 5 * sigma + half_digit)
        << names[k] << " truth " << run.truth.params[k];
  }

  // The RMS, and a line for every image with its outcome.
  char rms[32];
  std::snprintf(rms, sizeof(rms), "%.4f px per coordinate", run.result.rms_px);
  EXPECT_NE(markdown.find(rms), std::string::npos) << rms;
  for (size_t i = 0; i < run.input.images.size(); ++i) {
    const ReportImage& image = run.input.images[i];
    const std::string outcome =
        i == 0 ? "unreadable" : (i == 1 ? "no corners" : "used");
    const std::string line = "| " + std::to_string(i + 1) + " | " + image.file +
                             " | " + outcome + " | " +
                             std::to_string(image.corners_detected) + " | ";
    EXPECT_NE(markdown.find(line), std::string::npos) << line;
  }
  // The worst view heads the worst-views table.
  char worst[64];
  std::snprintf(worst, sizeof(worst), "| %d | view_%02d.png | %.3f |",
                by_rms[0] + 3, by_rms[0], run.result.view_rms_px[by_rms[0]]);
  const size_t worst_section = markdown.find("## Worst views");
  ASSERT_NE(worst_section, std::string::npos);
  EXPECT_EQ(markdown.find("| ", markdown.find("|---:|", worst_section) + 1),
            markdown.find(worst, worst_section))
      << worst;
  // Timing and the plot list.
  EXPECT_NE(markdown.find("| whole run | 2.50 |"), std::string::npos);
  // Every picture is embedded in summary.md, and index.html holds each one
  // inline: the bytes of its data: URI are the file's.
  ASSERT_EQ(summary.files.size() > 1 ? summary.files[1] : "", "index.html");
  const std::string page = ReadFile(report_dir / "index.html");
  int inlined = 0;
  for (const std::string& file : summary.files) {
    if (file == "summary.md" || file == "index.html") continue;
    EXPECT_NE(markdown.find("](" + file + ")"), std::string::npos) << file;
    ++inlined;
  }
  const std::string data_uri = "src=\"data:image/png;base64,";
  std::vector<std::string> decoded;
  for (size_t at = page.find(data_uri); at != std::string::npos;
       at = page.find(data_uri, at + 1)) {
    const size_t begin = at + data_uri.size();
    decoded.push_back(
        Base64Decode(page.substr(begin, page.find('"', begin) - begin)));
  }
  ASSERT_EQ(static_cast<int>(decoded.size()), inlined);
  for (const std::string& file : summary.files) {
    if (file == "summary.md" || file == "index.html") continue;
    EXPECT_NE(
        std::find(decoded.begin(), decoded.end(), ReadFile(report_dir / file)),
        decoded.end())
        << file << " is not inlined byte for byte";
  }
  RemoveUnlessKept(dir);
}

// Loads `page` in Debian's chromium, headless, and returns what a script
// added to a copy of it finds: "decoded N of M" images (every <img> that
// finished loading with a width); "" when chromium cannot be run.
std::string ImagesDecodedInChromium(const fs::path& page,
                                    const fs::path& scratch) {
  const std::string check =
      "<script>window.addEventListener('load', () => {"
      "const images = Array.from(document.images);"
      "const decoded = images.filter(i => i.complete && i.naturalWidth > 0);"
      "document.title = 'decoded ' + decoded.length + ' of ' + "
      "images.length;});</script>";
  std::string html = ReadFile(page);
  const size_t body_end = html.rfind("</body>");
  if (body_end == std::string::npos) return "no </body>";
  html.insert(body_end, check);
  const fs::path copy = scratch / "check.html";
  testing_files::WriteFile(copy, html);
  const fs::path dom = scratch / "dom.html";
  const std::string command =
      "chromium --headless --no-sandbox --disable-gpu --disable-dev-shm-usage "
      "--no-first-run "
      "--user-data-dir=" +
      (scratch / "profile").string() +
      " --virtual-time-budget=10000 --dump-dom 'file://" + copy.string() +
      "' >'" + dom.string() + "' 2>/dev/null";
  if (std::system(command.c_str()) != 0) return "";
  const std::string out = ReadFile(dom);
  const size_t title = out.find("<title>");
  if (title == std::string::npos) return "";
  return out.substr(title + 7, out.find("</title>", title) - title - 7);
}

// The page a report writes, opened in a real browser: every picture in it
// decodes (issue: the report as a page, checked in a headless browser).
TEST(ReportTest, IndexHtmlShowsEveryPictureInABrowser) {
  if (std::system("command -v chromium >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "chromium is not installed (scripts/install_deps.sh "
                    "--full installs it)";
  }
  const fs::path dir = FreshDir("browser");
  const fs::path image_dir = dir / "images";
  fs::create_directories(image_dir);
  SyntheticRun run;
  MakeRun(SmallRadtanScene(), image_dir, /*render=*/true, &run);
  ASSERT_TRUE(run.calibrated) << run.calibrate_error;
  std::string error;
  ReportSummary summary;
  const fs::path report_dir = dir / "report";
  ASSERT_TRUE(WriteReport(report_dir.string(), run.input, ReportOptions(),
                          &error, &summary))
      << error;
  int pictures = 0;
  for (const std::string& file : summary.files) {
    pictures += file.size() > 4 && file.substr(file.size() - 4) == ".png";
  }
  ASSERT_GT(pictures, 5);
  EXPECT_EQ(ImagesDecodedInChromium(report_dir / "index.html", dir),
            "decoded " + std::to_string(pictures) + " of " +
                std::to_string(pictures));
  RemoveUnlessKept(dir);
}

TEST(ReportTest, FisheyeRunWithMissingImagesStillWritesEverything) {
  const fs::path dir = FreshDir("fisheye");
  sim::SyntheticScene scene;
  scene.camera = sim::MakeCamera(
      CameraModelId::kKannalaBrandt, 800, 600,
      {247.5, 247.1, 400.9, 299.2, 0.02, -0.005, 0.001, -0.0002});
  scene.num_views = 10;
  scene.noise_px = 0.1;
  scene.max_direction_deg = 85;
  scene.max_corner_angle_deg = 110;
  scene.min_visible_fraction = 0.3;
  scene.min_tilt_deg = 0;
  scene.max_tilt_deg = 60;
  scene.min_distance = 0.8;
  scene.max_distance = 1.6;
  scene.seed = 3;
  SyntheticRun run;
  MakeRun(scene, dir / "missing", /*render=*/false, &run);
  ASSERT_TRUE(run.calibrated) << run.calibrate_error;
  // A failed run is reported too: the summary must say so.
  run.input.calibration_ok = false;
  run.input.calibration_error = "too few views tilted by 30 deg or more";
  ReportOptions options;
  options.num_overlays = 1;
  std::string error;
  ReportSummary summary;
  ASSERT_TRUE(WriteReport((dir / "report").string(), run.input, options, &error,
                          &summary))
      << error;
  // The overlay image is missing: drawn on grey, with a warning naming it.
  ASSERT_EQ(summary.warnings.size(), 1u);
  EXPECT_NE(summary.warnings[0].find("missing"), std::string::npos)
      << summary.warnings[0];
  int overlays = 0;
  for (const std::string& file : summary.files) {
    EXPECT_TRUE(fs::exists(dir / "report" / file)) << file;
    if (file.rfind("overlay_", 0) == 0) {
      ++overlays;
      EXPECT_EQ(PngSize(dir / "report" / file).width, options.overlay_width);
    }
  }
  EXPECT_EQ(overlays, 1);
  EXPECT_EQ(PngSize(dir / "report" / "distortion.png").width,
            options.image_plot_width);
  const std::string markdown = ReadFile(dir / "report" / "summary.md");
  EXPECT_NE(markdown.find("**Calibration failed:** too few views tilted"),
            std::string::npos);
  EXPECT_NE(markdown.find("kannala-brandt"), std::string::npos);
  EXPECT_NE(markdown.find("equidistant"), std::string::npos);
  RemoveUnlessKept(dir);
}

// The distortion map's shift, cross-checked against OpenCV's undistortion.
TEST(ReportTest, DistortionShiftAgreesWithOpenCv) {
  const Camera radtan = sim::MakeCamera(
      CameraModelId::kPinholeRadtan, 640, 480,
      {410.0, 409.3, 321.2, 238.6, -0.28, 0.09, 0.0006, -0.0004, -0.012});
  const Camera fisheye = sim::MakeCamera(
      CameraModelId::kKannalaBrandt, 800, 600,
      {247.5, 247.1, 400.9, 299.2, 0.02, -0.005, 0.001, -0.0002});
  for (const Camera& camera : {radtan, fisheye}) {
    const auto& p = camera.params;
    const cv::Matx33d k(p[0], 0, p[2], 0, p[1], p[3], 0, 0, 1);
    // For the fisheye, pixels up to about 75 degrees off the axis, where
    // OpenCV's fisheye model (which divides by z) is valid.
    const std::vector<Eigen::Vector2d> pixels =
        camera.model == CameraModelId::kPinholeRadtan
            ? std::vector<Eigen::Vector2d>{{40, 40},
                                           {600, 60},
                                           {320, 240},
                                           {150, 400}}
            : std::vector<Eigen::Vector2d>{
                  {150, 200}, {600, 40}, {420, 310}, {650, 450}};
    for (const Eigen::Vector2d& pixel : pixels) {
      double shift = 0, angle = 0;
      ASSERT_TRUE(DistortionShift(camera, pixel, &shift, &angle));
      std::vector<cv::Point2d> in = {{pixel.x(), pixel.y()}}, out;
      Eigen::Vector2d ideal;
      if (camera.model == CameraModelId::kPinholeRadtan) {
        cv::undistortPoints(in, out, k,
                            std::vector<double>{p[4], p[5], p[6], p[7], p[8]},
                            cv::noArray(), cv::noArray(),
                            cv::TermCriteria(cv::TermCriteria::COUNT, 100, 0));
        ideal = Eigen::Vector2d(p[0] * out[0].x + p[2], p[1] * out[0].y + p[3]);
        EXPECT_NEAR(angle,
                    std::atan(std::hypot(out[0].x, out[0].y)) * 180 / M_PI,
                    1e-4);
      } else {
        cv::fisheye::undistortPoints(
            in, out, k, std::vector<double>{p[4], p[5], p[6], p[7]},
            cv::noArray(), cv::noArray(),
            cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS,
                             100, 1e-14));
        const double r = std::hypot(out[0].x, out[0].y);
        const double theta = std::atan(r);
        ideal = Eigen::Vector2d(p[0] * theta * out[0].x / r + p[2],
                                p[1] * theta * out[0].y / r + p[3]);
        EXPECT_NEAR(angle, theta * 180 / M_PI, 1e-4);
      }
      EXPECT_NEAR(shift, (ideal - pixel).norm(), 1e-3)
          << CameraModelName(camera.model) << " at " << pixel.transpose();
    }
  }
  // No ray for a non-finite pixel.
  double shift = 0, angle = 0;
  EXPECT_FALSE(DistortionShift(radtan, Eigen::Vector2d(std::nan(""), 3), &shift,
                               &angle));
}

TEST(ReportTest, FormatWithSigmaKeepsThreeDigitsOfSigma) {
  std::string sigma;
  EXPECT_EQ(FormatWithSigma(820.123456, 0.0123, &sigma), "820.1235");
  EXPECT_EQ(sigma, "0.0123");
  EXPECT_EQ(FormatWithSigma(-0.28000417, 0.000212, &sigma), "-0.280004");
  EXPECT_EQ(sigma, "0.000212");
  EXPECT_EQ(FormatWithSigma(1234.5, 25.0, &sigma), "1234.5");
  EXPECT_EQ(sigma, "25.0");
  EXPECT_EQ(FormatWithSigma(1.25, 0, &sigma), "1.25");
  EXPECT_EQ(sigma, "");
}

TEST(ReportTest, RefusesBadInputWithAMessage) {
  const fs::path dir = FreshDir("bad");
  ReportInput input;
  std::string error;
  EXPECT_FALSE(
      WriteReport((dir / "r").string(), input, ReportOptions(), &error));
  EXPECT_NE(error.find("no calibration result"), std::string::npos) << error;
  EXPECT_NE(ReportMarkdown(input, ReportOptions(), {}).find("No consistent"),
            std::string::npos);

  // A result that does not match the view list.
  CalibrationResult result;
  std::vector<CalibrationView> views(2);
  input.result = &result;
  input.views = &views;
  EXPECT_FALSE(
      WriteReport((dir / "r").string(), input, ReportOptions(), &error));
  EXPECT_NE(error.find("view"), std::string::npos) << error;

  // The folder's place is taken by a file.
  views.clear();
  result.camera.width = 640;
  result.camera.height = 480;
  std::ofstream((dir / "file").string()) << "x";
  EXPECT_FALSE(
      WriteReport((dir / "file").string(), input, ReportOptions(), &error));
  EXPECT_NE(error.find((dir / "file").string()), std::string::npos) << error;

  ReportOptions options;
  options.histogram_bins = 0;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("histogram_bins"), std::string::npos);
  EXPECT_FALSE(WriteReport((dir / "r").string(), input, options, &error));

  // An empty calibration (no views, default camera) still gives a summary.
  ASSERT_TRUE(
      WriteReport((dir / "empty").string(), input, ReportOptions(), &error))
      << error;
  EXPECT_TRUE(fs::exists(dir / "empty" / "summary.md"));
  RemoveUnlessKept(dir);
}

// One record per image: what the pipeline and then the calibration made of
// it, as the report's table shows it.
TEST(ReportTest, ImageRecordsSayWhatTheCalibrationMadeOfEachView) {
  std::vector<ImageResult> images(3);
  images[0].file = "a.png";
  images[0].outcome = ImageOutcome::kNoGrid;
  images[0].reason = "no lattice";
  images[1].file = "b.png";
  images[1].outcome = ImageOutcome::kUsable;
  images[1].view_index = 0;
  images[1].corners.resize(7);
  images[2].file = "c.png";
  images[2].outcome = ImageOutcome::kUsable;
  images[2].view_index = 1;
  CalibrationResult result;
  result.view_used = {true, false};
  result.view_reason = {"", "too few inliers"};
  result.inlier = {{true, false, true, true}, {}};

  const std::vector<ReportImage> lines = MakeReportImages(images, &result);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].use, ViewUse::kNoView);
  EXPECT_EQ(lines[0].OutcomeText(), "no consistent grid");
  EXPECT_EQ(lines[0].reason, "no lattice");
  EXPECT_EQ(lines[1].use, ViewUse::kUsed);
  EXPECT_EQ(lines[1].OutcomeText(), "used");
  EXPECT_EQ(lines[1].corners_used, 3);
  EXPECT_EQ(lines[1].corners_detected, 7);
  EXPECT_EQ(lines[2].use, ViewUse::kDropped);
  EXPECT_EQ(lines[2].OutcomeText(), "not used by the calibration");
  EXPECT_EQ(lines[2].reason, "too few inliers");

  // A failed calibration: the pipeline's outcomes stand.
  const std::vector<ReportImage> failed = MakeReportImages(images, nullptr);
  EXPECT_EQ(failed[1].use, ViewUse::kNoView);
  EXPECT_EQ(failed[1].OutcomeText(), "usable");
}

}  // namespace
}  // namespace puzzlecal
