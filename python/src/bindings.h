#ifndef PUZZLECAL_PYTHON_SRC_BINDINGS_H_
#define PUZZLECAL_PYTHON_SRC_BINDINGS_H_

// The Python module puzzlecal._puzzlecal, one Bind function per library
// folder it covers (as the folders, so the bindings): target (boards),
// pipeline (detection on arrays and files), camera + formats (cameras and
// their files), evidence (calibration and its judgement). Errors are raised
// as ValueError with the program's messages; long work releases the GIL.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <algorithm>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "camera/camera_models.h"
#include "evidence/evidence.h"

namespace puzzlecal::python {

namespace py = pybind11;

void BindTarget(py::module_& m);
void BindDetection(py::module_& m);
void BindCamera(py::module_& m);
void BindCalibration(py::module_& m);
void BindRig(py::module_& m);

// The evidence's tables of one camera's calibration (halves, uncertainty,
// residual means by field angle and distance), as the report shows them.
py::dict EvidenceDict(const Evidence& evidence);
// {parameter name: value} of the camera's model.
py::dict ByName(const Camera& camera, const std::vector<double>& values);
// Workers for `threads` (0: all cores); ValueError when negative.
int Threads(int threads);

// Raises ValueError(message).
[[noreturn]] void Raise(const std::string& message);

// An N x 2 (or N x 3) float64 array of the points.
py::array_t<double> PointsArray(const std::vector<Eigen::Vector2d>& points);
py::array_t<double> PointsArray(const std::vector<Eigen::Vector3d>& points);
py::array_t<int> IdsArray(const std::vector<Eigen::Vector2i>& ids);
// A matrix as a 2-D float64 array (a copy).
py::array_t<double> MatrixArray(const Eigen::MatrixXd& matrix);

// A single-channel cv::Mat of element type T (uint8_t for CV_8UC1, float
// for CV_32FC1) as a rows x cols array (a copy, row by row: the Mat may
// have a row step).
template <typename T>
py::array_t<T> MatArray(const cv::Mat& mat) {
  py::array_t<T> out({mat.rows, mat.cols});
  for (int r = 0; r < mat.rows; ++r) {
    std::copy(mat.ptr<T>(r), mat.ptr<T>(r) + mat.cols, out.mutable_data(r, 0));
  }
  return out;
}

// Rows of an N x `cols` array of numbers (any real dtype, converted to
// float64); ValueError naming `what` for any other shape or dtype.
std::vector<Eigen::Vector2d> Points2(const py::handle& array, const char* what);
std::vector<Eigen::Vector3d> Points3(const py::handle& array, const char* what);
// An N x 2 integer array.
std::vector<Eigen::Vector2i> Ids2(const py::handle& array, const char* what);

// A grey cv::Mat (CV_8UC1) of a numpy image: H x W uint8 (shared, no copy),
// H x W x 3 (BGR, as OpenCV loads) or H x W x 4 (BGRA) uint8 (converted to
// grey), H x W uint16 (scaled to 8 bits). ValueError for anything else.
// `keep` holds the array alive while the Mat is in use.
cv::Mat GreyImage(const py::handle& image, py::object* keep);

}  // namespace puzzlecal::python

#endif  // PUZZLECAL_PYTHON_SRC_BINDINGS_H_
