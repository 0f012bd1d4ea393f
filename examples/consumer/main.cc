// Calibrates a camera from photos of the 23 x 16 PuzzleBoard with the
// puzzlecal libraries: corners, lattice, board ids, then the calibration.
//
//   puzzlecal_consumer IMAGE...
//
// Prints the intrinsics and the RMS; exits 1 when there is no calibration.

#include <puzzlecal/calib/calibrate.h>
#include <puzzlecal/decode/decoder.h>
#include <puzzlecal/detection/detector.h>
#include <puzzlecal/grid/grid.h>
#include <puzzlecal/target/board.h>

#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  using namespace puzzlecal;
  const Board board = MakeBoard(BoardType::kPuzzleBoard, 23, 16,
                                Eigen::Vector2i(50, 100), 0.030);
  std::vector<CalibrationView> views;
  int width = 0, height = 0;
  for (int i = 1; i < argc; ++i) {
    const cv::Mat grey = cv::imread(argv[i], cv::IMREAD_GRAYSCALE);
    if (grey.empty()) {
      std::cerr << argv[i] << ": not readable\n";
      continue;
    }
    const std::vector<Corner> corners = DetectCorners(grey);
    const std::vector<GridComponent> grid = BuildGrid(corners, grey);
    const DecodeResult decoded = DecodeBoard(board, corners, grid, grey);
    std::cout << argv[i] << ": " << corners.size() << " corners, "
              << decoded.observation.id.size() << " with board ids\n";
    if (!decoded.decoded || decoded.observation.id.size() < 6) continue;
    CalibrationView view;
    view.name = argv[i];
    for (size_t k = 0; k < decoded.observation.id.size(); ++k) {
      view.board_points.push_back(board.Point(decoded.observation.id[k]));
      view.image_points.push_back(decoded.observation.xy[k]);
    }
    views.push_back(view);
    width = grey.cols;
    height = grey.rows;
  }
  CalibrationResult result;
  std::string error;
  if (!Calibrate(views, CameraModelId::kPinholeRadtan, width, height,
                 CalibrationOptions(), &result, &error)) {
    std::cerr << "no calibration: " << error << "\n";
    return 1;
  }
  const std::vector<double>& p = result.camera.params;
  std::cout << "fx " << p[0] << " fy " << p[1] << " cx " << p[2] << " cy "
            << p[3] << " k1 " << p[4] << "; RMS " << result.rms_px << " px\n";
  return 0;
}
