// Cameras: a model and its parameters, read from and written to every
// camera file format the program writes, projection, unprojection and
// undistortion maps for cv2.remap.

#include <pybind11/stl.h>

#include <cmath>
#include <limits>

#include "camera/camera_models.h"
#include "formats/camera_yaml.h"
#include "pipeline/undistort.h"
#include "python/src/bindings.h"

namespace puzzlecal::python {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Camera MakeCheckedCamera(const std::string& model, const py::handle& params,
                         int width, int height) {
  Camera camera;
  if (!CameraModelIdFromName(model, &camera.model)) {
    Raise("unknown model '" + model + "'; choose one of " + CameraModelNames());
  }
  const py::array_t<double, py::array::c_style | py::array::forcecast> values(
      py::array::ensure(params));
  if (!values || values.ndim() != 1) Raise("params: expected a 1-D array");
  camera.params.assign(values.data(), values.data() + values.size());
  if (static_cast<int>(camera.params.size()) !=
      CameraModelNumParams(camera.model)) {
    Raise(model + " has " + std::to_string(CameraModelNumParams(camera.model)) +
          " parameters, got " + std::to_string(camera.params.size()));
  }
  if (width < 1 || height < 1) Raise("width and height must be >= 1");
  camera.width = width;
  camera.height = height;
  return camera;
}

CameraFileFormat FormatNamed(const std::string& name) {
  CameraFileFormat format;
  if (!CameraFileFormatFromName(name, &format)) {
    Raise("unknown format '" + name +
          "'; choose one of puzzlecal, opencv, ros, kalibr");
  }
  return format;
}

}  // namespace

void BindCamera(py::module_& m) {
  py::class_<Camera>(m, "Camera",
                     "A camera model with its parameters and image size.")
      .def(py::init(&MakeCheckedCamera), py::arg("model"), py::arg("params"),
           py::arg("width"), py::arg("height"),
           "A camera of `model` (puzzlecal.MODELS) with its parameters in "
           "the model's order (param_names).")
      .def_static(
          "load",
          [](const std::string& path) {
            Camera camera;
            std::string error;
            if (!ReadCameraFile(path, &camera, &error)) Raise(error);
            return camera;
          },
          py::arg("path"),
          "Reads a camera file in any format the program writes (puzzlecal, "
          "opencv, ros, kalibr).")
      .def(
          "save",
          [](const Camera& camera, const std::string& path,
             const std::string& format) {
            std::string error, note;
            if (!WriteCameraFile(path, FormatNamed(format), camera,
                                 CameraFileStats(), &error, &note)) {
              Raise(error);
            }
            return note;
          },
          py::arg("path"), py::arg("format") = "puzzlecal",
          "Writes the camera atomically in `format`; returns a note on what "
          "the format leaves out ('' when nothing).")
      .def_property_readonly(
          "model",
          [](const Camera& c) { return std::string(CameraModelName(c.model)); })
      .def_property_readonly(
          "params",
          [](const Camera& c) {
            return py::array_t<double>(
                static_cast<py::ssize_t>(c.params.size()), c.params.data());
          },
          "the parameters, float64, in the model's order")
      .def_property_readonly(
          "param_names",
          [](const Camera& c) { return CameraModelParamNames(c.model); })
      .def_property_readonly(
          "params_by_name",
          [](const Camera& c) {
            py::dict named;
            const std::vector<std::string> names =
                CameraModelParamNames(c.model);
            for (size_t i = 0; i < names.size() && i < c.params.size(); ++i) {
              named[py::str(names[i])] = c.params[i];
            }
            return named;
          })
      .def_readonly("width", &Camera::width)
      .def_readonly("height", &Camera::height)
      .def_property_readonly(
          "central",
          [](const Camera& c) { return CameraModelIsCentral(c.model); },
          "every ray starts at the camera origin")
      .def(
          "project",
          [](const Camera& c, const py::handle& points) {
            const std::vector<Eigen::Vector3d> in = Points3(points, "points");
            std::vector<Eigen::Vector2d> out(in.size());
            for (size_t i = 0; i < in.size(); ++i) {
              if (!c.Project(in[i], &out[i])) out[i].setConstant(kNaN);
            }
            return PointsArray(out);
          },
          py::arg("points"),
          "Pixels of camera-frame points (N x 3, metres); NaN where the "
          "model cannot project a point.")
      .def(
          "unproject",
          [](const Camera& c, const py::handle& pixels) {
            const std::vector<Eigen::Vector2d> in = Points2(pixels, "pixels");
            std::vector<Eigen::Vector3d> out(in.size());
            for (size_t i = 0; i < in.size(); ++i) {
              if (!c.Unproject(in[i], &out[i]).converged) {
                out[i].setConstant(kNaN);
              }
            }
            return PointsArray(out);
          },
          py::arg("pixels"),
          "Unit ray directions (N x 3) of pixels (N x 2); for the non-central "
          "model the direction of the ray (its origin: unproject_rays); NaN "
          "where the inverse does not converge.")
      .def(
          "unproject_rays",
          [](const Camera& c, const py::handle& pixels) {
            const std::vector<Eigen::Vector2d> in = Points2(pixels, "pixels");
            std::vector<Eigen::Vector3d> origins(in.size()),
                directions(in.size());
            for (size_t i = 0; i < in.size(); ++i) {
              ViewingRay ray;
              if (c.UnprojectRay(in[i], &ray).converged) {
                origins[i] = ray.origin;
                directions[i] = ray.direction;
              } else {
                origins[i].setConstant(kNaN);
                directions[i].setConstant(kNaN);
              }
            }
            return py::make_tuple(PointsArray(origins),
                                  PointsArray(directions));
          },
          py::arg("pixels"),
          "(origins, directions), N x 3 each: the rays through pixels, "
          "origins 0 for central models.")
      .def(
          "undistort_maps",
          [](const Camera& c, double alpha, double max_angle_deg) {
            UndistortOptions options;
            options.alpha = alpha;
            options.max_angle_deg = max_angle_deg;
            std::string why;
            if (!options.Check(&why)) Raise("undistort: " + why);
            cv::Mat map_x, map_y;
            UndistortResult chosen;
            {
              py::gil_scoped_release release;
              chosen = ChooseUndistortTarget(c, options);
              MakeUndistortMaps(c, chosen.target, options, &map_x, &map_y);
            }
            return py::make_tuple(MatArray<float>(map_x),
                                  MatArray<float>(map_y), chosen.target);
          },
          py::arg("alpha") = 0.0, py::arg("max_angle_deg") = 60.0,
          "(map_x, map_y, target): float32 maps for cv2.remap(image, map_x, "
          "map_y, cv2.INTER_LINEAR) onto `target`, a distortion-free "
          "pinhole camera (alpha 0: no black border, 1: every invertible "
          "pixel; rays beyond max_angle_deg left out). -1 where no source "
          "pixel lies behind a target pixel.")
      .def("__repr__", [](const Camera& c) {
        return "<puzzlecal.Camera " + std::string(CameraModelName(c.model)) +
               " " + std::to_string(c.width) + "x" + std::to_string(c.height) +
               ">";
      });
  m.attr("MODELS") = [] {
    std::vector<std::string> names;
    for (CameraModelId id : kAllCameraModels)
      names.push_back(CameraModelName(id));
    return names;
  }();
}

}  // namespace puzzlecal::python
