#ifndef PUZZLECAL_APPS_COMMON_FLAGS_H_
#define PUZZLECAL_APPS_COMMON_FLAGS_H_

// Flags shared by several subcommands (gflags allows one definition each).

#include <gflags/gflags.h>

DECLARE_string(images);
DECLARE_string(board);
DECLARE_string(camera);
DECLARE_string(out);
DECLARE_string(model);
DECLARE_string(format);
DECLARE_string(report);
DECLARE_string(draw);
DECLARE_string(scene);
DECLARE_int32(threads);
DECLARE_int32(dpi);
DECLARE_string(rostopic);
DECLARE_string(camera_name);
DECLARE_string(options);
DECLARE_string(fix);
DECLARE_string(initial);
DECLARE_bool(same_focal);
DECLARE_double(knot_spacing_deg);

DECLARE_bool(quiet);
DECLARE_bool(verbose);

namespace puzzlecal {

// How much a subcommand prints (--quiet / --verbose; every subcommand takes
// them). Errors are always printed.
enum class Verbosity {
  kQuiet,    // errors and the line that says what was written
  kNormal,   // plus the result and each image problem, once
  kVerbose,  // plus every image and the timings
};
Verbosity ConsoleVerbosity();

}  // namespace puzzlecal

#endif  // PUZZLECAL_APPS_COMMON_FLAGS_H_
