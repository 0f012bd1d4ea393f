// `puzzlecal board`: writes a printable board (SVG, PDF or PNG).

#include <iostream>
#include <string>

#include "apps/common_flags.h"
#include "apps/config_io.h"
#include "apps/subcommand.h"
#include "util/atomic_file.h"
#include "sim/print_board.h"

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
  std::string bytes;
  if (!RenderPrintableBoard(board, format, options, &bytes, &error)) {
    std::cerr << "puzzlecal board: " << FLAGS_board << ": " << error << "\n";
    return kExitNoResult;
  }
  if (!WriteFileAtomically(FLAGS_out, bytes, &error)) {
    std::cerr << "puzzlecal board: " << error << "\n";
    return kExitOutputError;
  }
  double width_mm, height_mm;
  PrintedPageSizeMm(board, &width_mm, &height_mm);
  std::cout << FLAGS_out << ": " << width_mm << " x " << height_mm
            << " mm page, tile " << board.tile_size_m * 1000 << " mm\n";
  return kExitOk;
}

PUZZLECAL_REGISTER_SUBCOMMAND(
    board, "board", "write a printable board (SVG, PDF or PNG)",
    "puzzlecal board --board BOARD.yaml --out board.svg|board.pdf|board.png "
    "[--dpi 300]\n\n"
    "Lays the board out as the PuzzleBoard authors' generator does: the page\n"
    "is cols x rows tiles, corners half a tile in from the page edge, half\n"
    "tiles at the border, a disc of diameter s/3 on every edge between two\n"
    "printed corners (white = bit 1). A checkerboard page holds (cols + 1) x\n"
    "(rows + 1) full tiles. SVG and PDF have the exact physical size (print\n"
    "at 100 %); PNG is drawn at --dpi. The file is written atomically.",
    {"board", "out", "dpi"}, &RunBoard);

}  // namespace
}  // namespace puzzlecal
