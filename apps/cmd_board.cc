// `puzzlecal board`: writes a printable board page (SVG, PDF or PNG).

#include <filesystem>
#include <iostream>
#include <string>

#include "apps/common_flags.h"
#include "apps/subcommand.h"
#include "formats/board_file.h"
#include "sim/print_board.h"
#include "util/atomic_file.h"

DEFINE_string(page, "fit",
              "Sheet: a4, a3, letter, or fit (the pattern plus a printable "
              "margin and the label).");

namespace puzzlecal {
namespace {

int RunBoard() {
  if (FLAGS_board.empty() || FLAGS_out.empty()) {
    std::cerr << "puzzlecal board: --board and --out are required (see "
                 "puzzlecal board --help)\n";
    return kExitUsage;
  }
  PrintFormat format;
  if (!PrintFormatFromPath(FLAGS_out, &format)) {
    std::cerr << "puzzlecal board: --out " << FLAGS_out
              << ": the file must end in .svg, .pdf or .png\n";
    return kExitUsage;
  }
  PrintOptions options;
  options.dpi = FLAGS_dpi;
  if (!PageSizeFromName(FLAGS_page, &options.page) ||
      options.page == PageSize::kPatternOnly) {
    std::cerr << "puzzlecal board: --page " << FLAGS_page
              << ": choose a4, a3, letter or fit\n";
    return kExitUsage;
  }
  options.board_name = std::filesystem::path(FLAGS_board).filename().string();
  std::string error;
  if (!options.Check(&error)) {
    std::cerr << "puzzlecal board: --dpi: " << error << "\n";
    return kExitUsage;
  }
  Board board;
  if (!LoadBoardFile(FLAGS_board, &board, &error)) {
    std::cerr << "puzzlecal board: " << error << "\n";
    return kExitBadInput;
  }
  PageLayout layout;
  if (!LayOutPage(board, options, &layout, &error)) {
    std::cerr << "puzzlecal board: " << FLAGS_board << " does not fit --page "
              << FLAGS_page << ": " << error << "\n";
    return kExitUsage;
  }
  std::string bytes;
  if (!RenderPrintableBoard(board, format, options, &bytes, &error)) {
    std::cerr << "puzzlecal board: " << FLAGS_board << ": " << error << "\n";
    return kExitNoResult;
  }
  if (!WriteFileAtomically(FLAGS_out, bytes, &error)) {
    std::cerr << "puzzlecal board: " << error << "\n";
    return kExitOutputError;
  }
  if (ConsoleVerbosity() != Verbosity::kQuiet) {
    std::cout << FLAGS_out << ": " << layout.width_mm << " x "
              << layout.height_mm << " mm page (" << FLAGS_page << "), pattern "
              << layout.pattern_w_mm << " x " << layout.pattern_h_mm
              << " mm, tile " << board.tile_size_m * 1000
              << " mm. Print at 100 % (no 'fit to page'), then check the "
                 "100 mm scale bar with a ruler.\n";
  } else {
    std::cout << "wrote " << FLAGS_out << "\n";
  }
  return kExitOk;
}

PUZZLECAL_REGISTER_SUBCOMMAND(
    board, "board", "write a printable board page (SVG, PDF or PNG)",
    "puzzlecal board --board BOARD.yaml --out board.pdf|board.svg|board.png "
    "[--page a4|a3|letter|fit] [--dpi 300]\n\n"
    "Writes a page: the pattern centred on the sheet, a label line (board "
    "file, type,\ncols x rows, tile size, origin, \"print at 100 %\") and a "
    "100 mm scale bar. --page fit\nmakes the sheet just large enough (pattern, "
    "label and a 10 mm margin); a board that\ndoes not fit the sheet is "
    "refused with its size (exit 2). The pattern is laid out as\nthe "
    "PuzzleBoard authors' generator does: cols x rows tiles, corners half a "
    "tile in from\nthe pattern edge, a disc of diameter s/3 on every edge "
    "between two printed corners\n(white = bit 1); a checkerboard has (cols + "
    "1) x (rows + 1) full tiles. SVG and PDF\nhave the exact physical size; "
    "PNG is drawn at --dpi and stores it (pHYs). The file\nis written "
    "atomically.",
    {"board", "out", "page", "dpi"}, &RunBoard);

}  // namespace
}  // namespace puzzlecal
