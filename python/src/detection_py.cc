// Detection: corners, lattice and board ids of a numpy image or of image
// files (in parallel), and the run options by keyword.

#include <pybind11/stl.h>

#include "apps/options_io.h"
#include "formats/image_io.h"
#include "pipeline/pipeline.h"
#include "python/src/bindings.h"

namespace puzzlecal::python {
namespace {

// The options of a detection: the pipeline's, with decoding only when a
// board is given.
PipelineOptions DetectionOptions(const RunOptions& options, bool have_board) {
  PipelineOptions pipeline = options.pipeline;
  pipeline.run_decode = have_board;
  return pipeline;
}

}  // namespace

void BindDetection(py::module_& m) {
  py::class_<RunOptions>(
      m, "Options",
      "Every algorithmic option of a run (the sections of an options file: "
      "detector, grid, decode, load, pipeline, calibration, evidence, "
      "verdict, model_selection, rig). Make one with puzzlecal.options().")
      .def(py::init<>())
      .def("yaml", &OptionsYaml,
           "Every field with its value, as an options file.");
  m.def(
      "_parse_options",
      [](const std::string& text, const std::string& source) {
        RunOptions options;
        std::string error;
        if (!ParseOptionsText(text, source, &options, &error)) Raise(error);
        return options;
      },
      py::arg("text"), py::arg("source"));

  py::class_<ImageResult>(m, "Detection",
                          "What one image yielded: its corners, lattice "
                          "components and board ids.")
      .def_readonly("file", &ImageResult::file,
                    "the image file ('' for arrays)")
      .def_readonly("width", &ImageResult::width)
      .def_readonly("height", &ImageResult::height)
      .def_property_readonly(
          "outcome",
          [](const ImageResult& r) {
            return std::string(ImageOutcomeName(r.outcome));
          },
          "'usable', 'unreadable', 'no corners', 'no consistent grid', "
          "'code not recognised', 'too few corners', 'image size differs', "
          "'part of the board only' or 'repeated photo'")
      .def_property_readonly(
          "usable",
          [](const ImageResult& r) {
            return r.outcome == ImageOutcome::kUsable;
          },
          "enough corners with board ids to be a calibration view")
      .def_readonly("reason", &ImageResult::reason,
                    "why not usable, or details")
      .def_property_readonly(
          "decoded", [](const ImageResult& r) { return r.decode.absolute_ids; },
          "the ids are absolute board ids")
      .def_property_readonly(
          "ids",
          [](const ImageResult& r) {
            return IdsArray(r.decode.observation.id);
          },
          "board ids (col, row) of the identified corners, N x 2 int")
      .def_property_readonly(
          "corners",
          [](const ImageResult& r) {
            return PointsArray(r.decode.observation.xy);
          },
          "pixel positions of the identified corners, N x 2 float64 "
          "(OpenCV's convention: the top-left pixel's centre is (0, 0))")
      .def_property_readonly(
          "all_corners",
          [](const ImageResult& r) {
            std::vector<Eigen::Vector2d> xy;
            for (const Corner& c : r.corners) xy.push_back(c.xy);
            return PointsArray(xy);
          },
          "every detected corner, N x 2 float64, identified or not")
      .def_property_readonly(
          "seconds",
          [](const ImageResult& r) {
            return r.seconds_load + r.seconds_detect + r.seconds_grid_decode;
          },
          "time the library spent on this image (loading, detection, grid "
          "and decoding), seconds")
      .def_property_readonly(
          "num_components",
          [](const ImageResult& r) {
            return static_cast<int>(r.components.size());
          },
          "lattice components found")
      .def("__repr__", [](const ImageResult& r) {
        return "<puzzlecal.Detection " +
               (r.file.empty() ? std::string("array") : r.file) + ": " +
               ImageOutcomeName(r.outcome) + ", " +
               std::to_string(r.decode.observation.id.size()) + " ids>";
      });

  m.def(
      "detect",
      [](const py::handle& image, const Board* board,
         const RunOptions& options) {
        py::object keep;
        const cv::Mat grey = GreyImage(image, &keep);
        const PipelineOptions pipeline =
            DetectionOptions(options, board != nullptr);
        ImageResult result;
        {
          py::gil_scoped_release release;
          ProcessGreyImage(grey, board ? *board : Board(), pipeline, &result);
        }
        return result;
      },
      py::arg("image"), py::arg("board") = nullptr,
      py::arg("options") = RunOptions(),
      "Corners, lattice and (with a board) board ids of one image: a numpy "
      "array H x W (grey) or H x W x 3 (BGR), uint8, uint16 or float.");

  m.def(
      "load_image",
      [](const std::string& path) {
        cv::Mat grey;
        std::string error;
        bool ok = false;
        {
          py::gil_scoped_release release;
          ok = LoadGreyImage(path, ImageLoadOptions(), &grey, &error);
        }
        if (!ok) Raise(error);
        return MatArray<uint8_t>(grey);
      },
      py::arg("path"),
      "An image file as the program reads it: 8-bit grey, H x W uint8 "
      "(colour to luma, 16-bit scaled by the image's maximum).");
  m.def(
      "list_images",
      [](const std::string& path) {
        ImageListing listing;
        std::string error;
        if (!ListImages(path, &listing, &error)) Raise(error);
        return listing.images;
      },
      py::arg("path"),
      "The image files of a folder (sorted by name) or the one image file "
      "`path`, as the program lists them.");
  m.def(
      "detect_files",
      [](const std::vector<std::string>& files, const Board* board, int threads,
         const RunOptions& options) {
        if (threads < 0) Raise("threads must be >= 0 (0: all cores)");
        const PipelineOptions pipeline =
            DetectionOptions(options, board != nullptr);
        py::gil_scoped_release release;
        return ProcessImageFiles(files, board ? *board : Board(), pipeline,
                                 threads);
      },
      py::arg("files"), py::arg("board") = nullptr, py::arg("threads") = 0,
      py::arg("options") = RunOptions(),
      "detect() on image files, in parallel on `threads` workers (0: all "
      "cores), one image in memory per worker; results in the order of "
      "`files`, the same whatever the thread count. An unreadable file gives "
      "a Detection with outcome 'unreadable' and the reason.");
}

}  // namespace puzzlecal::python
