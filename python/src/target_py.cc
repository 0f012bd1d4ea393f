// Boards: load a board file, make one, its corner points, and its printable
// pattern as an image.

#include <pybind11/stl.h>

#include <opencv2/imgcodecs.hpp>

#include "formats/board_file.h"
#include "python/src/bindings.h"
#include "sim/print_board.h"
#include "target/board.h"

namespace puzzlecal::python {
namespace {

Board Checked(Board board) {
  std::string why;
  if (!board.Check(&why)) Raise("board: " + why);
  return board;
}

}  // namespace

void BindTarget(py::module_& m) {
  py::class_<Board>(m, "Board",
                    "A printed target: a PuzzleBoard (absolute corner ids "
                    "from its edge bits) or a plain checkerboard.")
      .def_static(
          "load",
          [](const std::string& path) {
            Board board;
            std::string error;
            if (!LoadBoardFile(path, &board, &error)) Raise(error);
            return board;
          },
          py::arg("path"),
          "Reads a board file (configs/boards/*.yaml): type, cols, rows, "
          "origin, tile_size_m.")
      .def_static(
          "puzzleboard",
          [](int cols, int rows, double tile_size_m,
             std::pair<int, int> origin) {
            return Checked(MakeBoard(
                BoardType::kPuzzleBoard, cols, rows,
                Eigen::Vector2i(origin.first, origin.second), tile_size_m));
          },
          py::arg("cols"), py::arg("rows"), py::arg("tile_size_m"),
          py::arg("origin") = std::pair<int, int>(0, 0),
          "A PuzzleBoard of cols x rows inner corners whose first corner is "
          "`origin` on the 501 x 501 code torus; tiles of tile_size_m metres.")
      .def_static(
          "checkerboard",
          [](int cols, int rows, double tile_size_m) {
            return Checked(MakeBoard(BoardType::kCheckerboard, cols, rows,
                                     Eigen::Vector2i::Zero(), tile_size_m));
          },
          py::arg("cols"), py::arg("rows"), py::arg("tile_size_m"),
          "A plain checkerboard of cols x rows inner corners.")
      .def_property_readonly(
          "type",
          [](const Board& b) { return std::string(BoardTypeName(b.type)); })
      .def_readonly("cols", &Board::cols, "inner corners along x")
      .def_readonly("rows", &Board::rows, "inner corners along y")
      .def_property_readonly(
          "origin",
          [](const Board& b) {
            return std::make_pair(b.origin.x(), b.origin.y());
          },
          "id of the first printed corner")
      .def_readonly("tile_size_m", &Board::tile_size_m, "tile edge, metres")
      .def_property_readonly("num_corners", &Board::NumCorners)
      .def(
          "ids", [](const Board& b) { return IdsArray(b.AllIds()); },
          "All printed corner ids, N x 2 int (col, row), row-major.")
      .def(
          "points",
          [](const Board& b, const py::handle& ids) {
            std::vector<Eigen::Vector3d> points;
            for (const Eigen::Vector2i& id : Ids2(ids, "ids")) {
              points.push_back(b.Point(id));
            }
            return PointsArray(points);
          },
          py::arg("ids"),
          "Board-frame points (metres, z = 0) of corner ids (N x 2 int).")
      .def(
          "render",
          [](const Board& b, double dpi) {
            PrintOptions options;
            options.dpi = dpi;
            std::string bytes, why;
            {
              py::gil_scoped_release release;
              if (!RenderPrintableBoard(b, PrintFormat::kPng, options, &bytes,
                                        &why)) {
                py::gil_scoped_acquire acquire;
                Raise("board render: " + why);
              }
            }
            const cv::Mat png(1, static_cast<int>(bytes.size()), CV_8UC1,
                              bytes.data());
            const cv::Mat grey = cv::imdecode(png, cv::IMREAD_GRAYSCALE);
            return MatArray<uint8_t>(grey);
          },
          py::arg("dpi") = 150.0,
          "The printable page as a grey uint8 image at `dpi` (what "
          "`puzzlecal board --out page.png` writes).")
      .def("__repr__", [](const Board& b) {
        return "<puzzlecal.Board " + std::string(BoardTypeName(b.type)) + " " +
               std::to_string(b.cols) + "x" + std::to_string(b.rows) + ", " +
               std::to_string(b.tile_size_m * 1000) + " mm>";
      });
}

}  // namespace puzzlecal::python
