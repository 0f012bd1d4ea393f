#include "apps/common_flags.h"

DEFINE_string(images, "",
              "Folder of images (png, jpg, tif, bmp), or one image file.");
DEFINE_string(board, "", "Board definition YAML (see configs/boards/).");
DEFINE_string(camera, "",
              "Camera file (any format puzzlecal reads: puzzlecal, opencv, "
              "ros, kalibr).");
DEFINE_string(out, "",
              "Output. calibrate: the camera file (.yaml); detect: the "
              "detections file (.yaml); board: the page (.svg, .pdf or .png); "
              "render, undistort, check and diff: a folder (created if "
              "missing). Files go into an existing, writable folder.");
DEFINE_string(model, "pinhole-radtan",
              "Camera model: pinhole-radtan, pinhole-rational, "
              "kannala-brandt, kannala-brandt-noncentral, "
              "kannala-brandt-splined, kannala-brandt-splined-noncentral, or "
              "auto (calibrate: chosen by held-out error).");
DEFINE_string(format, "puzzlecal",
              "Camera file format: puzzlecal, opencv, ros or kalibr.");
DEFINE_string(report, "", "Folder for the calibration report (optional).");
DEFINE_string(draw, "", "Folder for detection overlays (optional).");
DEFINE_string(scene, "",
              "A built-in scene by name (e.g. wide_pinhole) or a scene "
              "recipe YAML (see configs/scenes/README.md).");
DEFINE_int32(threads, 0, "Worker threads; 0 = all cores.");
DEFINE_int32(dpi, 300, "Resolution of PNG board output, dots per inch.");
DEFINE_string(rostopic, "/cam0/image_raw",
              "Image topic written into the kalibr camchain (cam0/rostopic).");
DEFINE_string(camera_name, "camera",
              "Camera name written into the ros camera_info file.");
DEFINE_string(options, "",
              "YAML options file (write one with `puzzlecal options`): "
              "detector, grid, decode, calibration, evidence, verdict, "
              "model_selection and rig settings; a field it leaves out keeps "
              "its default. --threads and --format (its fixed parameters) "
              "win over it.");
DEFINE_string(fix, "",
              "Parameters held at their start (comma-separated names such as "
              "k3,p1,p2, or the groups focal, principal-point, distortion, "
              "all), on top of the options file's calibration.fixed_params.");
DEFINE_string(initial, "",
              "Start from this camera file (any format puzzlecal reads); with "
              "--fix all only the poses are fitted. calibrate-rig: "
              "NAME=FILE,... per camera folder.");
DEFINE_bool(same_focal, false,
            "One focal length, fy = fx (square pixels; OpenCV's "
            "CALIB_FIX_ASPECT_RATIO with an aspect of 1); the options "
            "file's calibration.same_focal_length. calibrate-rig: every "
            "camera.");
DEFINE_double(knot_spacing_deg, 0,
              "A splined model's knot spacing, degrees of the equidistant "
              "image: the 10x10 grid then reaches 3.5 times as far. 0: "
              "from the data (the grid just covers the corners' field). "
              "Wider is smoother; a spacing whose grid would not reach the "
              "widest corner is refused. The options file's "
              "calibration.spline_knot_spacing_deg.");
DEFINE_bool(quiet, false, "Print only errors and what was written.");
DEFINE_bool(verbose, false,
            "Print every image's outcome and the timings as well.");

namespace puzzlecal {

Verbosity ConsoleVerbosity() {
  if (FLAGS_quiet) return Verbosity::kQuiet;
  return FLAGS_verbose ? Verbosity::kVerbose : Verbosity::kNormal;
}

}  // namespace puzzlecal
