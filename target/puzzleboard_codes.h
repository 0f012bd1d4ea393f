#ifndef PUZZLECAL_TARGET_PUZZLEBOARD_CODES_H_
#define PUZZLECAL_TARGET_PUZZLEBOARD_CODES_H_

namespace puzzlecal {

inline constexpr int kPuzzleBoardCodeRows = 3;
inline constexpr int kPuzzleBoardCodeLength = 167;
// 3 * 167: ids on the PuzzleBoard torus are taken modulo this.
inline constexpr int kPuzzleBoardPeriod = 501;

// The published base codes, one string of '0'/'1' per row (167 characters).
extern const char* const kPuzzleBoardCodeA[kPuzzleBoardCodeRows];
extern const char* const kPuzzleBoardCodeB[kPuzzleBoardCodeRows];

}  // namespace puzzlecal

#endif  // PUZZLECAL_TARGET_PUZZLEBOARD_CODES_H_
