#include "apps/common_flags.h"

DEFINE_string(images, "", "Folder of images, or one image file.");
DEFINE_string(board, "", "Board definition YAML (see configs/boards/).");
DEFINE_string(out, "", "Output file or folder.");
DEFINE_string(model, "pinhole-radtan",
              "Camera model: pinhole-radtan, pinhole-rational, "
              "kannala-brandt or kannala-brandt-noncentral.");
DEFINE_string(format, "puzzlecal",
              "Camera file format: puzzlecal, opencv, ros or kalibr.");
DEFINE_string(report, "", "Folder for the calibration report (optional).");
DEFINE_string(draw, "", "Folder for detection overlays (optional).");
DEFINE_string(scene, "", "Scene recipe YAML (see configs/scenes/).");
DEFINE_int32(threads, 0, "Worker threads; 0 = all cores.");
DEFINE_int32(dpi, 300, "Resolution of PNG board output, dots per inch.");
