#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan, libraries
# instrumented for coverage) into build-fuzz/ and runs each for a bounded
# time from its committed seed corpus (fuzz/corpus/<target>/), copied to a
# temporary working corpus so the repository is not modified.
#
#   scripts/fuzz.sh [seconds_per_target] [target ...]
#
# Prints libFuzzer's final "#N DONE cov: ... ft: ..." line per target. A crash
# leaves its input in build-fuzz/crashes/<target>/ and makes the script fail.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-30}"
shift || true
build_dir="${PUZZLECAL_FUZZ_BUILD_DIR:-build-fuzz}"
# clang and its libFuzzer runtime come with the full set of packages.
scripts/install_deps.sh --full

# The sanitizer build type (CMakeLists.txt): -O2 with line tables only, as
# the sanitizer test run; full debug information (RelWithDebInfo) took the
# compiler far longer on the solvers' templates, and a finding's stack needs
# only the lines.
if [ ! -f "$build_dir/CMakeCache.txt" ]; then
  generator=()
  if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
  CC=clang CXX=clang++ cmake -S . -B "$build_dir" "${generator[@]}" \
    -DPUZZLECAL_BUILD_FUZZ=ON -DPUZZLECAL_BUILD_TESTS=OFF \
    -DPUZZLECAL_BUILD_BENCH=OFF -DPUZZLECAL_BUILD_PYTHON=OFF \
    -DCMAKE_BUILD_TYPE=Asan
fi

all_targets=(detect_fuzzer grid_decode_fuzzer config_yaml_fuzzer camera_yaml_fuzzer)
requested=("${all_targets[@]}")
if [ $# -gt 0 ]; then requested=("$@"); fi
targets=()
for t in "${requested[@]}"; do
  # Targets whose reader has not been written yet are not configured.
  if [ -d "$build_dir/fuzz/CMakeFiles/$t.dir" ]; then
    targets+=("$t")
  else
    echo "fuzz: $t not configured (its reader is missing), skipped"
  fi
done
cmake --build "$build_dir" --parallel "$(nproc)" --target "${targets[@]}"

# Findings must stop the run; leaks count. The image decoders may not
# allocate more than 16 Mpixel per image inside the fuzzers.
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:print_stacktrace=1:abort_on_error=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export OPENCV_IO_MAX_IMAGE_PIXELS=16777216
export OPENCV_LOG_LEVEL=ERROR

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
status=0
summary=()
for t in "${targets[@]}"; do
  corpus="$work/$t"
  mkdir -p "$corpus" "$build_dir/crashes/$t"
  if [ -d "fuzz/corpus/$t" ]; then cp -r "fuzz/corpus/$t/." "$corpus/"; fi
  log="$build_dir/crashes/$t.log"
  echo "fuzz: $t for ${seconds}s"
  if "$build_dir/fuzz/$t" "$corpus" -max_total_time="$seconds" \
      -rss_limit_mb=2048 -timeout=10 -max_len=16384 -print_final_stats=1 \
      -artifact_prefix="$build_dir/crashes/$t/" >"$log" 2>&1; then
    line="$(grep -E '^#[0-9]+[[:space:]]+DONE' "$log" | tail -1 | tr '\t' ' ' || true)"
    summary+=("$t: ${line:-no DONE line, see $log}")
  else
    status=1
    summary+=("$t: FAILED, see $log and $build_dir/crashes/$t/")
    tail -60 "$log"
  fi
done
echo "fuzz summary (${seconds}s per target):"
printf '  %s\n' "${summary[@]}"
exit "$status"
