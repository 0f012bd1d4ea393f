#include "target/puzzleboard.h"

#include <array>

namespace puzzlecal {
namespace {

using CodeTable = std::array<std::array<unsigned char, kPuzzleBoardCodeLength>,
                             kPuzzleBoardCodeRows>;

CodeTable Unpack(const char* const rows[kPuzzleBoardCodeRows]) {
  CodeTable table{};
  for (int r = 0; r < kPuzzleBoardCodeRows; ++r) {
    for (int c = 0; c < kPuzzleBoardCodeLength; ++c) {
      table[r][c] = rows[r][c] == '1' ? 1 : 0;
    }
  }
  return table;
}

const CodeTable& TableA() {
  static const CodeTable table = Unpack(kPuzzleBoardCodeA);
  return table;
}

const CodeTable& TableB() {
  static const CodeTable table = Unpack(kPuzzleBoardCodeB);
  return table;
}

}  // namespace

int PuzzleBoardCodeABit(int row, int col) { return TableA()[row][col]; }
int PuzzleBoardCodeBBit(int row, int col) { return TableB()[row][col]; }

}  // namespace puzzlecal
