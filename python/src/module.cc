#include <glog/logging.h>

#include <cstdlib>

#include "formats/image_io.h"
#include "python/src/bindings.h"

namespace puzzlecal::python {

void Raise(const std::string& message) { throw py::value_error(message); }

py::array_t<double> PointsArray(const std::vector<Eigen::Vector2d>& points) {
  py::array_t<double> out(
      {static_cast<py::ssize_t>(points.size()), static_cast<py::ssize_t>(2)});
  auto view = out.mutable_unchecked<2>();
  for (size_t i = 0; i < points.size(); ++i) {
    view(i, 0) = points[i].x();
    view(i, 1) = points[i].y();
  }
  return out;
}

py::array_t<double> PointsArray(const std::vector<Eigen::Vector3d>& points) {
  py::array_t<double> out(
      {static_cast<py::ssize_t>(points.size()), static_cast<py::ssize_t>(3)});
  auto view = out.mutable_unchecked<2>();
  for (size_t i = 0; i < points.size(); ++i) {
    for (int k = 0; k < 3; ++k) view(i, k) = points[i](k);
  }
  return out;
}

py::array_t<int> IdsArray(const std::vector<Eigen::Vector2i>& ids) {
  py::array_t<int> out(
      {static_cast<py::ssize_t>(ids.size()), static_cast<py::ssize_t>(2)});
  auto view = out.mutable_unchecked<2>();
  for (size_t i = 0; i < ids.size(); ++i) {
    view(i, 0) = ids[i].x();
    view(i, 1) = ids[i].y();
  }
  return out;
}

py::array_t<double> MatrixArray(const Eigen::MatrixXd& matrix) {
  py::array_t<double> out({static_cast<py::ssize_t>(matrix.rows()),
                           static_cast<py::ssize_t>(matrix.cols())});
  auto view = out.mutable_unchecked<2>();
  for (Eigen::Index r = 0; r < matrix.rows(); ++r) {
    for (Eigen::Index c = 0; c < matrix.cols(); ++c) view(r, c) = matrix(r, c);
  }
  return out;
}

namespace {

// The array as N x cols float64, or ValueError.
py::array_t<double> RealRows(const py::handle& handle, int cols,
                             const char* what) {
  if (!py::isinstance<py::array>(handle) && !py::isinstance<py::list>(handle) &&
      !py::isinstance<py::tuple>(handle)) {
    Raise(std::string(what) + ": expected an N x " + std::to_string(cols) +
          " array, got " + std::string(py::str(handle.get_type())));
  }
  const py::array array = py::array::ensure(handle);
  if (!array) Raise(std::string(what) + ": not convertible to an array");
  const char kind = array.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    Raise(std::string(what) + ": expected real numbers, got dtype " +
          std::string(py::str(array.dtype())));
  }
  if (array.ndim() != 2 || array.shape(1) != cols) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < array.ndim(); ++d) {
      shape += (d ? ", " : "") + std::to_string(array.shape(d));
    }
    Raise(std::string(what) + ": expected shape (N, " + std::to_string(cols) +
          "), got " + shape + ")");
  }
  return py::array_t<double, py::array::c_style | py::array::forcecast>(array);
}

}  // namespace

std::vector<Eigen::Vector2d> Points2(const py::handle& handle,
                                     const char* what) {
  // The converted array must outlive the view of it.
  const py::array_t<double> converted = RealRows(handle, 2, what);
  const auto rows = converted.unchecked<2>();
  std::vector<Eigen::Vector2d> points(rows.shape(0));
  for (py::ssize_t i = 0; i < rows.shape(0); ++i) {
    points[i] = Eigen::Vector2d(rows(i, 0), rows(i, 1));
  }
  return points;
}

std::vector<Eigen::Vector3d> Points3(const py::handle& handle,
                                     const char* what) {
  const py::array_t<double> converted = RealRows(handle, 3, what);
  const auto rows = converted.unchecked<2>();
  std::vector<Eigen::Vector3d> points(rows.shape(0));
  for (py::ssize_t i = 0; i < rows.shape(0); ++i) {
    points[i] = Eigen::Vector3d(rows(i, 0), rows(i, 1), rows(i, 2));
  }
  return points;
}

std::vector<Eigen::Vector2i> Ids2(const py::handle& handle, const char* what) {
  const py::array array = py::array::ensure(handle);
  if (!array || (array.dtype().kind() != 'i' && array.dtype().kind() != 'u')) {
    Raise(std::string(what) + ": expected an N x 2 integer array");
  }
  const py::array_t<double> converted = RealRows(handle, 2, what);
  const auto rows = converted.unchecked<2>();
  std::vector<Eigen::Vector2i> ids(rows.shape(0));
  for (py::ssize_t i = 0; i < rows.shape(0); ++i) {
    ids[i] = Eigen::Vector2i(static_cast<int>(rows(i, 0)),
                             static_cast<int>(rows(i, 1)));
  }
  return ids;
}

cv::Mat GreyImage(const py::handle& handle, py::object* keep) {
  if (!py::isinstance<py::array>(handle)) {
    Raise("image: expected a numpy array (H x W grey or H x W x 3 BGR), got " +
          std::string(py::str(handle.get_type())));
  }
  const py::array array = py::array::ensure(handle, py::array::c_style);
  int depth = -1;
  if (array.dtype().is(py::dtype::of<uint8_t>())) depth = CV_8U;
  if (array.dtype().is(py::dtype::of<uint16_t>())) depth = CV_16U;
  if (array.dtype().is(py::dtype::of<float>())) depth = CV_32F;
  if (array.dtype().is(py::dtype::of<double>())) depth = CV_64F;
  const int channels = array.ndim() == 3 ? static_cast<int>(array.shape(2)) : 1;
  if (depth < 0 || array.ndim() < 2 || array.ndim() > 3 ||
      (channels != 1 && channels != 3 && channels != 4) || array.shape(0) < 1 ||
      array.shape(1) < 1) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < array.ndim(); ++d) {
      shape += (d ? ", " : "") + std::to_string(array.shape(d));
    }
    Raise(
        "image: expected H x W (grey), H x W x 3 (BGR) or H x W x 4 (BGRA) "
        "of uint8, uint16, float32 or float64; got dtype " +
        std::string(py::str(array.dtype())) + " and shape " + shape + ")");
  }
  *keep = array;
  const cv::Mat wrapped(
      static_cast<int>(array.shape(0)), static_cast<int>(array.shape(1)),
      CV_MAKETYPE(depth, channels), const_cast<void*>(array.data()));
  cv::Mat grey;
  std::string why;
  // The program's own conversion (formats/image_io.h): luma of BGR, other
  // depths scaled by the image's maximum.
  if (!GreyFromImage(wrapped, &grey, &why)) Raise("image: " + why);
  return grey;
}

}  // namespace puzzlecal::python

PYBIND11_MODULE(_puzzlecal, m) {
  m.doc() =
      "puzzlecal: camera calibration from photos of a PuzzleBoard or a "
      "checkerboard (the compiled part; import puzzlecal).";
  puzzlecal::python::BindTarget(m);
  puzzlecal::python::BindDetection(m);
  puzzlecal::python::BindCamera(m);
  puzzlecal::python::BindCalibration(m);
  puzzlecal::python::BindRig(m);
  // Library logging (Ceres' solver warnings during the model choice) shows
  // only errors, as in the program without --verbose; GLOG_minloglevel in
  // the environment keeps its say.
  if (std::getenv("GLOG_minloglevel") == nullptr) {
    FLAGS_minloglevel = google::GLOG_ERROR;
  }
}
