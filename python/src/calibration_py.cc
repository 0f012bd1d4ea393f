// Calibration: views from detections or from (ids, corners) pairs, the
// model by name or chosen (`auto`), the calibration and its judgement
// (evidence/judgement.h, the program's steps), and the result with numpy
// arrays that outlives everything it came from.

#include <pybind11/stl.h>

#include <filesystem>
#include <thread>

#include "advice/advice.h"
#include "apps/options_io.h"
#include "evidence/judgement.h"
#include "formats/camera_yaml.h"
#include "pipeline/pipeline.h"
#include "python/src/bindings.h"
#include "report/advice_report.h"

namespace puzzlecal::python {
namespace {

// A calibration with everything its camera file needs; owns its data.
struct PyCalibration {
  Board board;
  std::vector<CalibrationView> views;
  std::vector<std::string> view_files;
  JudgedCalibration judged;
};

// A CV_8UC3 image as an H x W x 3 uint8 array (BGR, as OpenCV keeps it;
// a copy).
py::array_t<uint8_t> BgrArray(const cv::Mat& image) {
  py::array_t<uint8_t> out({image.rows, image.cols, 3});
  for (int r = 0; r < image.rows; ++r) {
    std::copy(image.ptr<uint8_t>(r), image.ptr<uint8_t>(r) + 3 * image.cols,
              out.mutable_data(r, 0, 0));
  }
  return out;
}

py::dict UncertaintyDict(const FieldUncertainty& u) {
  py::dict d;
  d["worst_px"] = u.worst_px;
  d["median_px"] = u.median_px;
  d["worst_band_median_px"] = u.worst_band_median_px;
  return d;
}

// The advice as a dict (the fields of advice.yaml, the outlines and the
// pictures as arrays).
py::dict AdviceDict(const Advice& advice, const PyCalibration& c) {
  py::dict d;
  d["field_radius_px"] = advice.field_radius_px;
  d["field_deg"] = advice.field_deg;
  d["noise_sigma_px"] = advice.noise_sigma_px;
  d["views_taken"] = advice.views_taken;
  d["uncertainty_now"] = UncertaintyDict(advice.now);
  d["target_uncertainty_px"] = advice.target_uncertainty_px;
  d["photos_to_target"] = advice.photos_to_target >= 0
                              ? py::object(py::int_(advice.photos_to_target))
                              : py::object(py::none());
  d["candidates"] = advice.candidate_poses.size();
  const std::vector<Eigen::Vector2d> seen =
      SeenCorners(c.views, c.judged.result);
  py::list views;
  for (size_t k = 0; k < advice.views.size(); ++k) {
    const AdvisedView& v = advice.views[k];
    py::dict view;
    view["words"] = v.words;
    view["R"] = MatrixArray(v.cam_from_board.linear());
    view["t"] = MatrixArray(v.cam_from_board.translation()).reshape({3});
    view["centre_px"] = MatrixArray(v.centre_px).reshape({2});
    view["distance_m"] = v.distance_m;
    view["tilt_deg"] = v.tilt_deg;
    view["tilt_direction_deg"] = v.tilt_direction_deg;
    view["visible_corners"] = v.visible_corners;
    view["outline_px"] = PointsArray(v.outline_px);
    view["expected_after"] = UncertaintyDict(v.after);
    view["picture"] =
        BgrArray(DrawAdvicePicture(advice, static_cast<int>(k), seen, 1200));
    views.append(view);
  }
  d["views"] = views;
  d["text"] = advice.Text();
  return d;
}

// A pose (R, t) given from Python: R a rotation (3 x 3), t 3 values.
Eigen::Isometry3d PoseFrom(const py::handle& pose, const char* what) {
  const py::tuple pair = py::cast<py::tuple>(pose);
  if (pair.size() != 2) Raise(std::string(what) + ": expected a pair (R, t)");
  const std::vector<Eigen::Vector3d> rows = Points3(pair[0], what);
  const std::vector<Eigen::Vector3d> t =
      Points3(py::array::ensure(pair[1]).attr("reshape")(-1, 3), what);
  if (rows.size() != 3 || t.size() != 1) {
    Raise(std::string(what) + ": R must be 3 x 3 and t 3 values");
  }
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) out.linear().row(r) = rows[r].transpose();
  out.translation() = t[0];
  const Eigen::Matrix3d R = out.linear();
  if (!((R * R.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
        std::abs(R.determinant() - 1.0) < 1e-6)) {
    Raise(std::string(what) + ": R is not a rotation");
  }
  return out;
}

}  // namespace

int Threads(int threads) {
  if (threads < 0) Raise("threads must be >= 0 (0: all cores)");
  return threads > 0 ? threads
                     : static_cast<int>(
                           std::max(1u, std::thread::hardware_concurrency()));
}

namespace {

// The advice's options as the program sets them from a run's options: its
// verdict's target, the spline prior the calibration had.
AdviceOptions AdviceOptionsFor(const RunOptions& options, double field_deg,
                               int threads, const std::string& what) {
  AdviceOptions advice = options.advice;
  advice.field_deg = field_deg;
  advice.num_threads = Threads(threads);
  advice.target_uncertainty_px = options.verdict.max_uncertainty_px;
  advice.target_min_views = options.verdict.min_views;
  advice.spline_prior = options.calibration.spline_prior;
  std::string why;
  if (!advice.Check(&why)) Raise(what + ": " + why);
  return advice;
}

}  // namespace

namespace {

PyCalibration Run(const Board& board, std::vector<CalibrationView> views,
                  std::vector<std::string> view_files, int width, int height,
                  const std::string& model, const RunOptions& options,
                  int threads) {
  if (views.empty()) {
    Raise("no usable view: every image lacks enough corners with board ids");
  }
  PyCalibration run;
  run.board = board;
  run.views = std::move(views);
  run.view_files = std::move(view_files);
  CalibrationOptions calibration = options.calibration;
  calibration.num_threads = Threads(threads);  // the same result, faster
  JudgementOptions judgement;
  judgement.evidence = options.evidence;
  judgement.verdict = options.verdict;
  judgement.model_selection = options.model_selection;
  std::string error;
  bool ok = false;
  {
    py::gil_scoped_release release;
    ok = CalibrateAndJudge(run.views, width, height, model, calibration,
                           judgement, &run.judged, &error);
  }
  if (!ok) Raise("calibration failed: " + error);
  return run;
}

PyCalibration FromDetections(const std::vector<ImageResult>& detections,
                             const Board& board, const std::string& model,
                             const RunOptions& options, int threads) {
  std::vector<ImageResult> images = detections;
  for (size_t i = 0; i < images.size(); ++i) {
    if (images[i].file.empty()) images[i].file = "image_" + std::to_string(i);
  }
  int width = 0, height = 0;
  std::vector<CalibrationView> views =
      MakeCalibrationViews(board, &images, &width, &height);
  std::vector<std::string> files = ViewFiles(images, views.size());
  return Run(board, std::move(views), std::move(files), width, height, model,
             options, threads);
}

PyCalibration FromObservations(const py::list& observations, const Board& board,
                               std::pair<int, int> image_size,
                               const std::string& model,
                               const RunOptions& options, int threads) {
  if (image_size.first < 1 || image_size.second < 1) {
    Raise("image_size must be (width, height) in pixels");
  }
  std::vector<CalibrationView> views;
  std::vector<std::string> files;
  for (size_t v = 0; v < observations.size(); ++v) {
    const std::string what = "observations[" + std::to_string(v) + "]";
    const py::handle item = observations[v];
    if (!py::isinstance<py::tuple>(item) && !py::isinstance<py::list>(item)) {
      Raise(what + ": expected (ids, corners)");
    }
    const py::sequence pair = py::reinterpret_borrow<py::sequence>(item);
    if (pair.size() != 2) Raise(what + ": expected (ids, corners)");
    const py::object ids_array = pair[0], corners_array = pair[1];
    const std::vector<Eigen::Vector2i> ids =
        Ids2(ids_array, (what + " ids").c_str());
    const std::vector<Eigen::Vector2d> corners =
        Points2(corners_array, (what + " corners").c_str());
    if (ids.size() != corners.size()) {
      Raise(what + ": " + std::to_string(ids.size()) + " ids but " +
            std::to_string(corners.size()) + " corners");
    }
    CalibrationView view;
    view.name = "view_" + std::to_string(v);
    for (size_t k = 0; k < ids.size(); ++k) {
      if (!board.Contains(ids[k])) {
        Raise(what + ": id (" + std::to_string(ids[k].x()) + ", " +
              std::to_string(ids[k].y()) + ") is not on the board");
      }
      view.board_points.push_back(board.Point(ids[k]));
      view.image_points.push_back(corners[k]);
    }
    files.push_back(view.name);
    views.push_back(std::move(view));
  }
  return Run(board, std::move(views), std::move(files), image_size.first,
             image_size.second, model, options, threads);
}

// A PixelMap as a rows x cols float64 array (NaN outside the field).
py::array_t<double> MapArray(const PixelMap& map) {
  py::array_t<double> out({map.rows, map.cols});
  for (int j = 0; j < map.rows; ++j) {
    for (int i = 0; i < map.cols; ++i) *out.mutable_data(j, i) = map.At(i, j);
  }
  return out;
}

py::list Bands(const std::vector<AngleBand>& bands) {
  py::list out;
  for (const AngleBand& b : bands) {
    out.append(py::dict(py::arg("lo_deg") = b.lo_deg,
                        py::arg("hi_deg") = b.hi_deg,
                        py::arg("count") = b.count,
                        py::arg("median") = b.median, py::arg("p95") = b.p95));
  }
  return out;
}

py::list Bins(const std::vector<ResidualBin>& bins) {
  py::list out;
  for (const ResidualBin& b : bins) {
    out.append(py::dict(py::arg("lo") = b.lo, py::arg("hi") = b.hi,
                        py::arg("count") = b.count,
                        py::arg("mean_radial_px") = b.mean_radial_px,
                        py::arg("mean_tangential_px") = b.mean_tangential_px,
                        py::arg("se_radial_px") = b.se_radial_px,
                        py::arg("se_tangential_px") = b.se_tangential_px,
                        py::arg("rms_px") = b.rms_px));
  }
  return out;
}

}  // namespace

py::dict EvidenceDict(const Evidence& e) {
  const CrossValidation& cv = e.cross_validation;
  py::dict halves(py::arg("ok") = cv.ok, py::arg("error") = cv.error,
                  py::arg("splits") = cv.splits,
                  py::arg("views") = py::make_tuple(cv.views_a, cv.views_b),
                  py::arg("rms_px") = py::make_tuple(cv.rms_a_px, cv.rms_b_px),
                  py::arg("rotation_deg") = cv.rotation_deg,
                  py::arg("difference_px") = MapArray(cv.difference_px),
                  py::arg("expected_px") = MapArray(cv.expected_px),
                  py::arg("difference_bands") = Bands(cv.difference_bands),
                  py::arg("expected_bands") = Bands(cv.expected_bands),
                  py::arg("intrinsics_chi2") = cv.intrinsics_chi2,
                  py::arg("intrinsics_dof") = cv.intrinsics_dof);
  py::list points;
  for (const UncertaintyPoint& p : e.uncertainty.points) {
    points.append(py::dict(
        py::arg("label") = p.label, py::arg("angle_deg") = p.angle_deg,
        py::arg("in_image") = p.in_image, py::arg("sigma_px") = p.sigma_px));
  }
  py::dict uncertainty(py::arg("ok") = e.uncertainty.ok,
                       py::arg("sigma_px") = MapArray(e.uncertainty.sigma_px),
                       py::arg("step_px") = e.uncertainty.sigma_px.step_px,
                       py::arg("bands") = Bands(e.uncertainty.bands),
                       py::arg("points") = points);
  return py::dict(
      py::arg("halves") = halves, py::arg("uncertainty") = uncertainty,
      py::arg("residuals_by_angle") = Bins(e.residuals.by_angle),
      py::arg("residuals_by_distance") = Bins(e.residuals.by_distance));
}

py::dict ByName(const Camera& camera, const std::vector<double>& values) {
  py::dict named;
  const std::vector<std::string> names = CameraModelParamNames(camera.model);
  for (size_t i = 0; i < names.size() && i < values.size(); ++i) {
    named[py::str(names[i])] = values[i];
  }
  return named;
}

void BindCalibration(py::module_& m) {
  py::class_<Verdict>(m, "Verdict",
                      "What the evidence says about a calibration: kind "
                      "('good', 'model-error', 'bad-detections', "
                      "'insufficient-data'), the reason with its figures, "
                      "the next step.")
      .def_property_readonly(
          "kind",
          [](const Verdict& v) { return std::string(VerdictKindName(v.kind)); })
      .def_readonly("reason", &Verdict::reason)
      .def_readonly("next_step", &Verdict::next_step)
      .def_readonly("findings", &Verdict::findings)
      .def_readonly("notes", &Verdict::notes)
      .def_readonly("suggested_model", &Verdict::suggested_model)
      .def("line", &Verdict::Line, "the one-line form the program prints")
      .def("__repr__", [](const Verdict& v) {
        return "<puzzlecal.Verdict " + std::string(VerdictKindName(v.kind)) +
               ">";
      });

  py::class_<PyCalibration>(m, "Calibration",
                            "A calibration, its judgement and every figure "
                            "behind them, as numpy arrays.")
      .def_property_readonly(
          "camera",
          [](const PyCalibration& c) { return c.judged.result.camera; })
      .def_property_readonly(
          "model",
          [](const PyCalibration& c) {
            return std::string(CameraModelName(c.judged.result.camera.model));
          })
      .def_property_readonly("params_by_name",
                             [](const PyCalibration& c) {
                               return ByName(c.judged.result.camera,
                                             c.judged.result.camera.params);
                             })
      .def_property_readonly(
          "stddev_by_name",
          [](const PyCalibration& c) {
            return ByName(c.judged.result.camera, c.judged.result.param_stddev);
          },
          "1-sigma of every parameter (0 for fixed ones)")
      .def_property_readonly(
          "covariance",
          [](const PyCalibration& c) {
            return MatrixArray(c.judged.result.covariance);
          },
          "covariance of the intrinsics (param_names order)")
      .def_property_readonly(
          "rms_px",
          [](const PyCalibration& c) { return c.judged.result.rms_px; },
          "RMS of the inlier residuals per coordinate, pixels")
      .def_property_readonly(
          "num_outliers",
          [](const PyCalibration& c) { return c.judged.result.num_outliers; })
      .def_property_readonly(
          "view_names",
          [](const PyCalibration& c) { return c.judged.result.view_name; })
      .def_property_readonly("view_used",
                             [](const PyCalibration& c) {
                               return std::vector<bool>(
                                   c.judged.result.view_used.begin(),
                                   c.judged.result.view_used.end());
                             })
      .def_property_readonly(
          "view_reasons",
          [](const PyCalibration& c) { return c.judged.result.view_reason; },
          "why a view was not used ('' when used)")
      .def_property_readonly(
          "poses",
          [](const PyCalibration& c) {
            py::list poses;
            for (const Eigen::Isometry3d& pose :
                 c.judged.result.cam_from_board) {
              poses.append(
                  py::make_tuple(MatrixArray(pose.linear()),
                                 MatrixArray(pose.translation()).reshape({3})));
            }
            return poses;
          },
          "per view (R, t): cam_from_board, P_cam = R @ P_board + t (metres)")
      .def_property_readonly(
          "residuals",
          [](const PyCalibration& c) {
            py::list out;
            for (const auto& r : c.judged.result.residuals) {
              out.append(PointsArray(r));
            }
            return out;
          },
          "per view, projected minus observed pixel (N x 2)")
      .def_property_readonly(
          "inliers",
          [](const PyCalibration& c) {
            py::list out;
            for (const std::vector<bool>& mask : c.judged.result.inlier) {
              py::array_t<bool> a(static_cast<py::ssize_t>(mask.size()));
              for (size_t i = 0; i < mask.size(); ++i)
                a.mutable_at(i) = mask[i];
              out.append(a);
            }
            return out;
          },
          "per view, whether each corner was kept")
      .def_property_readonly(
          "verdict",
          [](const PyCalibration& c) { return c.judged.judgement.verdict; })
      .def_property_readonly(
          "evidence",
          [](const PyCalibration& c) {
            return EvidenceDict(c.judged.judgement.evidence);
          },
          "the evidence behind the verdict: halves (two calibrations from "
          "halves of the views and their difference map against what noise "
          "gives), uncertainty (the projection's 1-sigma map and by field "
          "angle), residual means by field angle and by distance")
      .def_property_readonly(
          "model_selection",
          [](const PyCalibration& c) -> py::object {
            if (!c.judged.auto_model) return py::none();
            return py::str(c.judged.selection.Table());
          },
          "the held-out comparison of the models (model='auto'), as the "
          "program prints it; None otherwise")
      .def("summary",
           [](const PyCalibration& c) { return c.judged.result.FullReport(); })
      .def(
          "advise",
          [](const PyCalibration& c, int count, double field_deg,
             const RunOptions& options, int threads) {
            AdviceOptions advice_options =
                AdviceOptionsFor(options, field_deg, threads, "advise");
            advice_options.count = count;
            std::string why;
            if (!advice_options.Check(&why)) Raise("advise: " + why);
            Advice advice;
            {
              py::gil_scoped_release release;
              advice = AdviseViews(c.views, c.judged.result, c.board,
                                   advice_options);
            }
            if (!advice.ok) Raise("advise: " + advice.error);
            return AdviceDict(advice, c);
          },
          py::arg("count") = 4, py::arg("field_deg") = 0.0,
          py::arg("options") = RunOptions(), py::arg("threads") = 0,
          "Which photos to take next, as `puzzlecal advise` says: the `count` "
          "board poses that lower the projection uncertainty the most, "
          "chosen one by one. Returns a dict: uncertainty_now, "
          "photos_to_target (None when not within reach), and views, each "
          "with words, R and t (cam_from_board), centre_px, distance_m, "
          "tilt_deg, tilt_direction_deg, outline_px (the board's border in "
          "the image), expected_after and picture (an image as next_K.png "
          "shows it). field_deg limits the judged field (0: the default).")
      .def(
          "predict",
          [](const PyCalibration& c, const py::list& poses, double field_deg,
             const RunOptions& options) {
            const AdviceOptions advice_options =
                AdviceOptionsFor(options, field_deg, 1, "predict");
            std::vector<Eigen::Isometry3d> cam_from_board;
            for (const py::handle& pose : poses) {
              cam_from_board.push_back(PoseFrom(pose, "predict: pose"));
            }
            FieldUncertainty after;
            std::string error;
            bool ok = false;
            {
              py::gil_scoped_release release;
              ok = PredictWithPoses(c.views, c.judged.result, c.board,
                                    cam_from_board, advice_options, &after,
                                    &error);
            }
            if (!ok) Raise("predict: " + error);
            return UncertaintyDict(after);
          },
          py::arg("poses"), py::arg("field_deg") = 0.0,
          py::arg("options") = RunOptions(),
          "The projection uncertainty the advice predicts after adding "
          "photos of the board from `poses` (a list of (R, t), "
          "cam_from_board as `poses` and advise() give them) to the views "
          "used: a dict of worst_px, median_px and worst_band_median_px over "
          "the judged field, as advise() reports expected_after. For "
          "comparing the advised views with poses of your own choosing.")
      .def(
          "save",
          [](const PyCalibration& c, const std::string& path,
             const std::string& format) {
            CameraFileFormat file_format;
            if (!CameraFileFormatFromName(format, &file_format)) {
              Raise("unknown format '" + format +
                    "'; choose one of puzzlecal, opencv, ros, kalibr");
            }
            const CameraFileStats stats =
                CalibrationFileStats(c.judged.result, c.views, c.view_files,
                                     c.board.Point(c.board.origin),
                                     c.judged.judgement.verdict.Line());
            std::string error, note;
            if (!WriteCameraFile(path, file_format, c.judged.result.camera,
                                 stats, &error, &note)) {
              Raise(error);
            }
            return note;
          },
          py::arg("path"), py::arg("format") = "puzzlecal",
          "Writes the camera file as `puzzlecal calibrate` does (with its "
          "statistics, views and verdict); returns the format's note on "
          "what it leaves out ('' when nothing).");

  m.def("_calibrate_detections", &FromDetections, py::arg("detections"),
        py::arg("board"), py::arg("model"), py::arg("options"),
        py::arg("threads"));
  m.def("_calibrate_observations", &FromObservations, py::arg("observations"),
        py::arg("board"), py::arg("image_size"), py::arg("model"),
        py::arg("options"), py::arg("threads"));
}

}  // namespace puzzlecal::python
