#ifndef PUZZLECAL_DETECTION_VECTOR_CLONES_H_
#define PUZZLECAL_DETECTION_VECTOR_CLONES_H_

// The per-pixel loops gain from 256-bit vectors; with GCC on x86-64 a
// function marked PUZZLECAL_VECTOR_CLONES is compiled twice and the AVX2
// version is picked at load time when the processor has it (the default
// build targets baseline x86-64).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define PUZZLECAL_VECTOR_CLONES \
  __attribute__((target_clones("avx2", "default")))
#else
#define PUZZLECAL_VECTOR_CLONES
#endif

// Hand-written 256-bit code (functions marked __attribute__((target("avx2"))),
// called only when CpuHasAvx2()) on GCC and Clang for x86-64.
#if defined(__GNUC__) && defined(__x86_64__)
#define PUZZLECAL_AVX2_INTRINSICS 1
namespace puzzlecal {
inline bool CpuHasAvx2() {
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
}
}  // namespace puzzlecal
#endif

#endif  // PUZZLECAL_DETECTION_VECTOR_CLONES_H_
