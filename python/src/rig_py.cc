// Rig calibration: per-camera image folders (frames matched by file name or
// by order) or per-camera observations, a model per camera (or `auto`), the
// calibration and its judgement as `puzzlecal calibrate-rig` makes them
// (pipeline/rig_run.h), and the result with numpy arrays that outlives
// everything it came from. Also the rendered rigs of sim/ with their truth.

#include <pybind11/stl.h>

#include <filesystem>
#include <memory>
#include <optional>

#include "apps/options_io.h"
#include "formats/camera_yaml.h"
#include "formats/rig_yaml.h"
#include "pipeline/rig_run.h"
#include "python/src/bindings.h"
#include "sim/rig_scenes.h"

namespace puzzlecal::python {
namespace {

// A rig calibration with everything its rig file needs; owns its data.
struct PyRig {
  Board board;
  std::vector<RigCameraInput> inputs;
  std::vector<std::vector<std::string>> frame_files;  // per camera, frame
  std::vector<bool> auto_model;                       // per camera
  std::vector<ModelSelection> selections;             // per camera (auto)
  CameraFileFormat format = CameraFileFormat::kPuzzlecal;
  JudgedRig judged;
};

// One camera of a rig result (shares the result, so it outlives the call).
struct PyRigCamera {
  std::shared_ptr<const PyRig> rig;
  size_t index = 0;
  const RigCameraResult& Result() const {
    return rig->judged.result.cameras[index];
  }
};

py::tuple PoseTuple(const Eigen::Isometry3d& pose) {
  return py::make_tuple(MatrixArray(pose.linear()),
                        MatrixArray(pose.translation()).reshape({3}));
}

// What the caller asked for, checked before any image is read.
struct RigRequest {
  std::vector<std::string> names;  // per camera
  std::vector<CameraModelId> models;
  std::vector<bool> auto_model;
  CameraFileFormat format = CameraFileFormat::kPuzzlecal;
  std::string format_name;
  std::vector<std::vector<std::string>> format_fixed;  // per camera
};

RigRequest ParseRequest(const std::vector<std::string>& names,
                        const std::vector<std::string>& models,
                        const std::string& format) {
  RigRequest request;
  request.names = names;
  if (names.size() < 2) {
    Raise(std::to_string(names.size()) +
          " cameras (a rig needs one per camera, at least two)");
  }
  if (models.size() != 1 && models.size() != names.size()) {
    std::string held;
    for (const std::string& name : names) held += " " + name;
    Raise(std::to_string(models.size()) + " models for " +
          std::to_string(names.size()) +
          " cameras; give one model for all or one per camera (cameras:" +
          held + ")");
  }
  for (size_t c = 0; c < names.size(); ++c) {
    const std::string& name = models[models.size() == 1 ? 0 : c];
    CameraModelId id = CameraModelId::kPinholeRadtan;
    const bool is_auto = name == "auto";
    if (!is_auto && !CameraModelIdFromName(name, &id)) {
      Raise("unknown model '" + name + "'; choose one of " +
            CameraModelNames() + " or auto");
    }
    request.models.push_back(id);
    request.auto_model.push_back(is_auto);
  }
  if (!CameraFileFormatFromName(format, &request.format)) {
    Raise("unknown format '" + format +
          "'; choose one of puzzlecal, opencv, ros, kalibr");
  }
  request.format_name = format;
  request.format_fixed.resize(names.size());
  for (size_t c = 0; c < names.size(); ++c) {
    std::string error;
    if (!request.auto_model[c] &&
        !CameraFormatFixedParams(request.format, request.models[c],
                                 &request.format_fixed[c], &error)) {
      Raise("format " + format + ", camera '" + names[c] + "': " + error);
    }
  }
  return request;
}

// Chooses the `auto` models (with the GIL released), calibrates and judges.
std::shared_ptr<PyRig> Run(const Board& board, const RigRequest& request,
                           std::vector<RigCameraInput> inputs,
                           std::vector<std::vector<std::string>> frame_files,
                           const RunOptions& options, int threads) {
  auto rig = std::make_shared<PyRig>();
  rig->board = board;
  rig->auto_model = request.auto_model;
  rig->format = request.format;
  rig->selections.resize(inputs.size());
  RigRunOptions run;
  run.rig = options.rig;
  run.rig.camera.num_threads = Threads(threads);
  run.evidence = options.evidence;
  run.verdict = options.verdict;
  run.rig_evidence = options.rig_evidence;
  std::string error;
  bool ok = true;
  {
    py::gil_scoped_release release;
    for (size_t c = 0; c < inputs.size() && ok; ++c) {
      if (!request.auto_model[c]) continue;
      std::string why;
      if (!ChooseRigCameraModel(inputs[c], options.calibration,
                                options.model_selection, &rig->selections[c],
                                &why)) {
        error = "camera '" + inputs[c].name + "': model auto: " + why;
        ok = false;
        break;
      }
      const ModelSelection& selection = rig->selections[c];
      inputs[c].model = selection.candidates[selection.chosen].model;
      if (!CameraFormatFixedParams(request.format, inputs[c].model,
                                   &inputs[c].fixed_params, &why)) {
        error = "format " + request.format_name + ", camera '" +
                inputs[c].name + "' (model auto chose " +
                CameraModelName(inputs[c].model) + "): " + why;
        ok = false;
      }
    }
    if (ok) {
      ok = CalibrateAndJudgeRig(board, inputs, frame_files, run, &rig->judged,
                                &error);
      if (!ok) error = "no calibration: " + error;
    }
  }
  if (!ok) Raise(error);
  rig->inputs = std::move(inputs);
  rig->frame_files = std::move(frame_files);
  return rig;
}

std::shared_ptr<PyRig> FromFolders(const std::vector<std::string>& folders,
                                   std::vector<std::string> names,
                                   const Board& board,
                                   const std::vector<std::string>& models,
                                   bool match_by_order,
                                   const std::string& format,
                                   const RunOptions& options, int threads) {
  if (names.empty()) {
    for (const std::string& folder : folders) {
      // "cam0/" names the camera cam0 too.
      std::filesystem::path path(folder);
      if (!path.has_filename()) path = path.parent_path();
      names.push_back(path.filename().string());
    }
  }
  if (names.size() != folders.size()) {
    Raise(std::to_string(names.size()) + " names for " +
          std::to_string(folders.size()) + " camera folders");
  }
  const RigRequest request = ParseRequest(names, models, format);
  const size_t num_cameras = folders.size();
  std::vector<ImageListing> listings(num_cameras);
  for (size_t c = 0; c < num_cameras; ++c) {
    std::string error;
    if (!ListImages(folders[c], &listings[c], &error)) {
      Raise("camera '" + names[c] + "': " + error);
    }
  }
  RigFrames frames;
  std::string error;
  if (!MatchRigFrames(names, listings, match_by_order, &frames, &error)) {
    Raise(error);
  }
  std::vector<RigCameraInput> inputs(num_cameras);
  std::vector<std::vector<std::string>> frame_files(num_cameras);
  const int workers = Threads(threads);
  for (size_t c = 0; c < num_cameras; ++c) {
    inputs[c].name = names[c];
    inputs[c].model = request.models[c];
    inputs[c].fixed_params = request.format_fixed[c];
    int usable = 0;
    {
      py::gil_scoped_release release;
      usable = MakeRigCameraViews(
          board, listings[c].images, frames.frame_of_file[c], frames.num_frames,
          options.pipeline, workers, &inputs[c], &frame_files[c]);
    }
    if (usable == 0) {
      Raise("camera '" + names[c] + "' (" + folders[c] +
            "): no image shows the board; no calibration written.");
    }
  }
  return Run(board, request, std::move(inputs), std::move(frame_files), options,
             threads);
}

std::shared_ptr<PyRig> RigFromObservations(
    const py::list& observations, std::vector<std::string> names,
    const std::vector<std::pair<int, int>>& image_sizes, const Board& board,
    const std::vector<std::string>& models, const std::string& format,
    const RunOptions& options, int threads) {
  const size_t num_cameras = observations.size();
  if (names.empty()) {
    for (size_t c = 0; c < num_cameras; ++c) {
      names.push_back("cam" + std::to_string(c));
    }
  }
  if (names.size() != num_cameras) {
    Raise(std::to_string(names.size()) + " names for " +
          std::to_string(num_cameras) + " cameras");
  }
  if (image_sizes.size() != 1 && image_sizes.size() != num_cameras) {
    Raise("image_sizes: " + std::to_string(image_sizes.size()) + " sizes for " +
          std::to_string(num_cameras) +
          " cameras; give one (width, height) for all or one per camera");
  }
  const RigRequest request = ParseRequest(names, models, format);
  std::vector<RigCameraInput> inputs(num_cameras);
  std::vector<std::vector<std::string>> frame_files(num_cameras);
  size_t num_frames = 0;
  for (size_t c = 0; c < num_cameras; ++c) {
    const py::handle frames = observations[c];
    if (!py::isinstance<py::list>(frames) &&
        !py::isinstance<py::tuple>(frames)) {
      Raise("observations[" + std::to_string(c) + "] (camera '" + names[c] +
            "'): expected a list with one (ids, corners) or None per frame");
    }
    const py::sequence per_frame = py::reinterpret_borrow<py::sequence>(frames);
    if (c == 0) num_frames = per_frame.size();
    if (per_frame.size() != num_frames) {
      Raise("camera '" + names[c] + "': " + std::to_string(per_frame.size()) +
            " frames, camera '" + names[0] +
            "': " + std::to_string(num_frames) +
            "; every camera needs one entry per frame (None where it did not "
            "see the board)");
    }
    const std::pair<int, int> size =
        image_sizes[image_sizes.size() == 1 ? 0 : c];
    if (size.first < 1 || size.second < 1) {
      Raise("image_sizes: camera '" + names[c] +
            "': expected (width, height) in pixels");
    }
    RigCameraInput& input = inputs[c];
    input.name = names[c];
    input.model = request.models[c];
    input.fixed_params = request.format_fixed[c];
    input.width = size.first;
    input.height = size.second;
    input.frames.resize(num_frames);
    frame_files[c].assign(num_frames, "");
    for (size_t f = 0; f < num_frames; ++f) {
      const py::handle item = per_frame[f];
      if (item.is_none()) continue;
      const std::string what =
          "observations[" + std::to_string(c) + "][" + std::to_string(f) + "]";
      if (!py::isinstance<py::tuple>(item) && !py::isinstance<py::list>(item)) {
        Raise(what + ": expected (ids, corners) or None");
      }
      const py::sequence pair = py::reinterpret_borrow<py::sequence>(item);
      if (pair.size() != 2) Raise(what + ": expected (ids, corners) or None");
      const py::object ids_array = pair[0], corners_array = pair[1];
      const std::vector<Eigen::Vector2i> ids =
          Ids2(ids_array, (what + " ids").c_str());
      const std::vector<Eigen::Vector2d> corners =
          Points2(corners_array, (what + " corners").c_str());
      if (ids.size() != corners.size()) {
        Raise(what + ": " + std::to_string(ids.size()) + " ids but " +
              std::to_string(corners.size()) + " corners");
      }
      CalibrationView& view = input.frames[f];
      view.name = "frame_" + std::to_string(f);
      for (size_t k = 0; k < ids.size(); ++k) {
        if (!board.Contains(ids[k])) {
          Raise(what + ": id (" + std::to_string(ids[k].x()) + ", " +
                std::to_string(ids[k].y()) + ") is not on the board");
        }
        view.board_points.push_back(board.Point(ids[k]));
        view.image_points.push_back(corners[k]);
      }
      if (!view.board_points.empty()) frame_files[c][f] = view.name;
    }
  }
  return Run(board, request, std::move(inputs), std::move(frame_files), options,
             threads);
}

py::list FramesList(const PyRig& rig) {
  py::list out;
  const RigFileJudgement& file = rig.judged.file;
  for (size_t f = 0; f < file.frames.size(); ++f) {
    const RigFileFrame& frame = file.frames[f];
    const RigFrameEvidence& evidence = rig.judged.rig.frames[f];
    out.append(py::dict(
        py::arg("files") = frame.files, py::arg("use") = frame.use,
        py::arg("rms_px") = frame.rms_px, py::arg("compared") = frame.compared,
        py::arg("transfer_px") = frame.transfer_px,
        py::arg("pose_difference_mm") = frame.pose_difference_mm,
        py::arg("pose_difference_deg") = evidence.pose_difference_deg,
        py::arg("epipolar_px") = frame.epipolar_px,
        py::arg("moved") = frame.moved));
  }
  return out;
}

// The render's truth of a rig scene, as a dict.
py::dict RigTruth(const RigSceneSpec& scene, const RigRenderSummary& summary) {
  py::list cameras;
  for (const RigSceneCamera& camera : scene.cameras) {
    cameras.append(py::dict(
        py::arg("name") = camera.name, py::arg("camera") = camera.camera,
        py::arg("cam_from_rig") = PoseTuple(camera.cam_from_rig)));
  }
  py::list poses;
  for (const Eigen::Isometry3d& pose : RigFramePoses(scene)) {
    poses.append(PoseTuple(pose));
  }
  return py::dict(py::arg("name") = scene.name, py::arg("board") = scene.board,
                  py::arg("cameras") = cameras,
                  py::arg("rig_from_board") = poses,
                  py::arg("num_frames") = summary.num_frames,
                  py::arg("images_per_camera") = summary.images_per_camera);
}

}  // namespace

void BindRig(py::module_& m) {
  py::class_<RigVerdict>(
      m, "RigVerdict",
      "What the evidence says about a rig: kind ('good', 'moved-frames', "
      "'inconsistent', or a camera verdict's kind), the reason with its "
      "figures, the next step.")
      .def_readonly("kind", &RigVerdict::kind)
      .def_readonly("reason", &RigVerdict::reason)
      .def_readonly("next_step", &RigVerdict::next_step)
      .def("line", &RigVerdict::Line, "the one-line form the program prints")
      .def("__repr__", [](const RigVerdict& v) {
        return "<puzzlecal.RigVerdict " + v.kind + ">";
      });

  py::class_<PyRigCamera>(m, "RigCamera",
                          "One camera of a rig calibration: its intrinsics, "
                          "its place in the rig with sigmas, its residuals "
                          "and its own calibration's verdict.")
      .def_property_readonly(
          "name", [](const PyRigCamera& c) { return c.Result().name; })
      .def_property_readonly(
          "camera", [](const PyRigCamera& c) { return c.Result().camera; })
      .def_property_readonly(
          "model",
          [](const PyRigCamera& c) {
            return std::string(CameraModelName(c.Result().camera.model));
          })
      .def_property_readonly("params_by_name",
                             [](const PyRigCamera& c) {
                               return ByName(c.Result().camera,
                                             c.Result().camera.params);
                             })
      .def_property_readonly(
          "stddev_by_name",
          [](const PyRigCamera& c) {
            return ByName(c.Result().camera, c.Result().param_stddev);
          },
          "1-sigma of every parameter from the joint solve (0 for fixed ones)")
      .def_property_readonly(
          "cam_from_rig",
          [](const PyRigCamera& c) {
            return PoseTuple(c.Result().cam_from_rig);
          },
          "(R, t): P_cam = R @ P_rig + t (metres); identity for the "
          "reference camera (the first)")
      .def_property_readonly(
          "rotation_stddev_deg",
          [](const PyRigCamera& c) { return c.Result().rotation_stddev_deg; },
          "1-sigma of cam_from_rig's rotation, degrees (0 for the reference)")
      .def_property_readonly(
          "translation_stddev_m",
          [](const PyRigCamera& c) {
            return MatrixArray(c.Result().translation_stddev_m).reshape({3});
          },
          "1-sigma of each axis of cam_from_rig's t, metres")
      .def_property_readonly(
          "baseline_m",
          [](const PyRigCamera& c) { return c.Result().baseline_m; },
          "distance of the camera's centre from the reference camera's")
      .def_property_readonly(
          "baseline_stddev_m",
          [](const PyRigCamera& c) { return c.Result().baseline_stddev_m; })
      .def_property_readonly(
          "extrinsics_covariance",
          [](const PyRigCamera& c) {
            return MatrixArray(c.Result().extrinsics_covariance);
          },
          "6 x 6 covariance of cam_from_rig: angle-axis (rad), then t (m)")
      .def_property_readonly(
          "rms_px", [](const PyRigCamera& c) { return c.Result().rms_px; },
          "RMS of the camera's inlier residuals in the joint solve, pixels "
          "per coordinate")
      .def_property_readonly(
          "single_rms_px",
          [](const PyRigCamera& c) { return c.Result().single_rms_px; },
          "the same of the camera's own calibration")
      .def_property_readonly(
          "num_frames_used",
          [](const PyRigCamera& c) { return c.Result().num_frames_used; })
      .def_property_readonly(
          "num_corners_used",
          [](const PyRigCamera& c) { return c.Result().num_corners_used; })
      .def_property_readonly(
          "num_outliers",
          [](const PyRigCamera& c) { return c.Result().num_outliers; })
      .def_property_readonly(
          "frame_used",
          [](const PyRigCamera& c) {
            return std::vector<bool>(c.Result().frame_used.begin(),
                                     c.Result().frame_used.end());
          },
          "per frame, whether the camera took part in the joint solve")
      .def_property_readonly(
          "residuals",
          [](const PyRigCamera& c) {
            py::list out;
            for (const auto& r : c.Result().residuals)
              out.append(PointsArray(r));
            return out;
          },
          "per frame, projected minus observed pixel (N x 2; 0 x 2 where the "
          "camera did not take part)")
      .def_property_readonly(
          "inliers",
          [](const PyRigCamera& c) {
            py::list out;
            for (const std::vector<bool>& mask : c.Result().inlier) {
              py::array_t<bool> a(static_cast<py::ssize_t>(mask.size()));
              for (size_t i = 0; i < mask.size(); ++i)
                a.mutable_at(i) = mask[i];
              out.append(a);
            }
            return out;
          },
          "per frame, whether each corner was kept")
      .def_property_readonly(
          "frame_notes",
          [](const PyRigCamera& c) { return c.Result().frame_note; },
          "per frame, what was done (relabelled) or why the view was not "
          "used ('' when nothing to say)")
      .def_property_readonly(
          "verdict",
          [](const PyRigCamera& c) { return c.rig->judged.verdicts[c.index]; },
          "the verdict on the camera's own calibration, as `calibrate` "
          "judges one camera")
      .def_property_readonly(
          "evidence",
          [](const PyRigCamera& c) {
            return EvidenceDict(c.rig->judged.evidence[c.index]);
          },
          "the evidence behind that verdict (see Calibration.evidence)")
      .def_property_readonly(
          "model_selection",
          [](const PyRigCamera& c) -> py::object {
            if (!c.rig->auto_model[c.index]) return py::none();
            return py::str(c.rig->selections[c.index].Table());
          },
          "the held-out comparison that chose the model (model 'auto'), as "
          "the program prints it; None otherwise")
      .def("__repr__", [](const PyRigCamera& c) {
        return "<puzzlecal.RigCamera " + c.Result().name + " " +
               CameraModelName(c.Result().camera.model) + ">";
      });

  py::class_<PyRig, std::shared_ptr<PyRig>>(
      m, "RigCalibration",
      "A rig calibration, its judgement and the figures behind them, as "
      "numpy arrays.")
      .def_property_readonly(
          "cameras",
          [](const std::shared_ptr<PyRig>& rig) {
            py::list out;
            for (size_t c = 0; c < rig->judged.result.cameras.size(); ++c) {
              out.append(PyRigCamera{rig, c});
            }
            return out;
          },
          "the cameras (RigCamera) in input order; the first is the rig "
          "frame")
      .def_property_readonly(
          "camera_names",
          [](const PyRig& rig) {
            std::vector<std::string> names;
            for (const RigCameraResult& c : rig.judged.result.cameras) {
              names.push_back(c.name);
            }
            return names;
          })
      .def_property_readonly(
          "rms_px", [](const PyRig& rig) { return rig.judged.result.rms_px; },
          "RMS of every camera's inlier residuals, pixels per coordinate")
      .def_property_readonly(
          "num_frames_used",
          [](const PyRig& rig) { return rig.judged.result.num_frames_used; })
      .def_property_readonly(
          "num_corners_used",
          [](const PyRig& rig) { return rig.judged.result.num_corners_used; })
      .def_property_readonly(
          "num_outliers",
          [](const PyRig& rig) { return rig.judged.result.num_outliers; })
      .def_property_readonly(
          "covariance_ok",
          [](const PyRig& rig) { return rig.judged.result.covariance_ok; })
      .def_property_readonly(
          "frame_names",
          [](const PyRig& rig) { return RigFrameNames(rig.frame_files); },
          "per frame, its file name (the first camera's that exists)")
      .def_property_readonly(
          "frame_files", [](const PyRig& rig) { return rig.frame_files; },
          "per camera, per frame, its image file ('' where none)")
      .def_property_readonly("frame_used",
                             [](const PyRig& rig) {
                               return std::vector<bool>(
                                   rig.judged.result.frame_used.begin(),
                                   rig.judged.result.frame_used.end());
                             })
      .def_property_readonly(
          "poses",
          [](const PyRig& rig) {
            py::list out;
            const RigCalibrationResult& result = rig.judged.result;
            for (size_t f = 0; f < result.rig_from_board.size(); ++f) {
              if (f < result.frame_used.size() && result.frame_used[f]) {
                out.append(PoseTuple(result.rig_from_board[f]));
              } else {
                out.append(py::none());
              }
            }
            return out;
          },
          "per frame (R, t): rig_from_board, P_rig = R @ P_board + t "
          "(metres); None for a frame no camera took part in")
      .def_property_readonly(
          "shared_frames",
          [](const PyRig& rig) {
            const Eigen::MatrixXi& shared = rig.judged.result.shared_frames;
            py::array_t<int> out({shared.rows(), shared.cols()});
            for (Eigen::Index r = 0; r < shared.rows(); ++r) {
              for (Eigen::Index c = 0; c < shared.cols(); ++c) {
                *out.mutable_data(r, c) = shared(r, c);
              }
            }
            return out;
          },
          "frames each pair of cameras shares in the joint solve (C x C)")
      .def_property_readonly(
          "verdict", [](const PyRig& rig) { return rig.judged.rig_verdict; },
          "the rig's verdict (RigVerdict)")
      .def_property_readonly(
          "moved_frames",
          [](const PyRig& rig) { return rig.judged.rig.moved_frames; },
          "indices of the frames named as unsynchronised or moved")
      .def_property_readonly("frames", &FramesList,
                             "per frame: files and use per camera, RMS per "
                             "camera, and the consistency figures "
                             "(transfer_px, pose_difference_mm/deg, "
                             "epipolar_px, moved), as the rig file lists "
                             "them")
      .def("summary",
           [](const PyRig& rig) {
             return RigCalibrationReport(rig.judged.result);
           })
      .def(
          "save",
          [](const PyRig& rig, const std::string& path,
             const std::optional<std::string>& format) {
            CameraFileFormat file_format = rig.format;
            if (format && !CameraFileFormatFromName(*format, &file_format)) {
              Raise("unknown format '" + *format +
                    "'; choose one of puzzlecal, opencv, ros, kalibr");
            }
            std::vector<std::string> written;
            std::string error;
            if (!WriteRigFiles(path, file_format, rig.judged.result, &written,
                               &error, &rig.judged.file)) {
              Raise(error);
            }
            return written;
          },
          py::arg("path"), py::arg("format") = py::none(),
          "Writes the rig file as `puzzlecal calibrate-rig` does (the "
          "puzzlecal format with the verdict and the frames); format: "
          "puzzlecal, opencv, ros (one file per camera next to `path`) or "
          "kalibr, by default the one given to calibrate_rig. Returns the "
          "paths written.");

  m.def(
      "_rig_camera_folders",
      [](const std::string& root) {
        std::vector<std::string> folders;
        std::string error;
        if (!ListRigCameraFolders(root, &folders, &error)) Raise(error);
        return folders;
      },
      py::arg("root"));
  m.def("_calibrate_rig_folders", &FromFolders, py::arg("folders"),
        py::arg("names"), py::arg("board"), py::arg("models"),
        py::arg("match_by_order"), py::arg("format"), py::arg("options"),
        py::arg("threads"));
  m.def("_calibrate_rig_observations", &RigFromObservations,
        py::arg("observations"), py::arg("names"), py::arg("image_sizes"),
        py::arg("board"), py::arg("models"), py::arg("format"),
        py::arg("options"), py::arg("threads"));

  m.def(
      "render_rig",
      [](const std::string& folder, const std::string& scene_name,
         std::pair<int, int> size) {
        RigSceneSpec scene;
        if (scene_name == "stereo-pinhole") {
          scene = StereoPinholeRig(size.first, size.second);
        } else if (scene_name == "fisheye-pinhole") {
          scene = FisheyePinholeRig(size.first, size.second);
        } else if (scene_name == "stereo-fisheye") {
          scene = StereoFisheyeRig(size.first, size.second);
        } else if (scene_name == "four-cameras") {
          scene = FourCameraRig(size.first, size.second);
        } else {
          Raise("unknown rig scene '" + scene_name +
                "'; choose one of stereo-pinhole, fisheye-pinhole, "
                "stereo-fisheye, four-cameras");
        }
        RigRenderSummary summary;
        std::string why;
        bool ok = false;
        {
          py::gil_scoped_release release;
          ok = RenderRigScene(scene, folder, &summary, &why);
        }
        if (!ok) Raise("render_rig: " + why);
        return RigTruth(scene, summary);
      },
      py::arg("folder"), py::arg("scene") = "stereo-pinhole",
      py::arg("size") = std::pair<int, int>(640, 480),
      "Renders one of sim/'s rigs into folder/<camera>/frame_NNN.png (the "
      "same name in every camera folder is the same instant) and returns "
      "its truth: name, board, cameras (name, camera, cam_from_rig (R, t)), "
      "rig_from_board per frame, num_frames, images_per_camera.");
}

}  // namespace puzzlecal::python
