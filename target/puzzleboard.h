#ifndef PUZZLECAL_TARGET_PUZZLEBOARD_H_
#define PUZZLECAL_TARGET_PUZZLEBOARD_H_

// The PuzzleBoard pattern as docs/puzzleboard.md defines it: edge bits from the
// A and B codes, tile colours, ids on the 501 x 501 torus.

#include "target/puzzleboard_codes.h"

namespace puzzlecal {

// x mod n in [0, n), also for negative x.
inline int PositiveMod(int x, int n) {
  const int r = x % n;
  return r < 0 ? r + n : r;
}

// Bit A[row][col] (0 or 1); row in [0,3), col in [0,167).
int PuzzleBoardCodeABit(int row, int col);
// Bit B[row][col] (0 or 1); row in [0,3), col in [0,167).
int PuzzleBoardCodeBBit(int row, int col);

// Bit of the vertical edge from corner (x, y) to (x, y + 1):
// A[y mod 3][x mod 167]. 1 = white disc, 0 = black disc.
inline int PuzzleBoardVerticalEdgeBit(int x, int y) {
  return PuzzleBoardCodeABit(PositiveMod(y, 3),
                             PositiveMod(x, kPuzzleBoardCodeLength));
}

// Bit of the horizontal edge from corner (x, y) to (x + 1, y):
// B[x mod 3][y mod 167].
inline int PuzzleBoardHorizontalEdgeBit(int x, int y) {
  return PuzzleBoardCodeBBit(PositiveMod(x, 3),
                             PositiveMod(y, kPuzzleBoardCodeLength));
}

// Tile T(x, y) has corners (x, y) and (x + 1, y + 1); black when x + y is even.
inline bool PuzzleBoardTileIsBlack(int x, int y) {
  return PositiveMod(x + y, 2) == 0;
}

// Id component on the torus: x mod 501 in [0, 501).
inline int PuzzleBoardWrap(int x) { return PositiveMod(x, kPuzzleBoardPeriod); }

}  // namespace puzzlecal

#endif  // PUZZLECAL_TARGET_PUZZLEBOARD_H_
