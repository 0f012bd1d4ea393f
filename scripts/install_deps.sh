#!/usr/bin/env bash
# Installs the Debian 12 packages that puzzlecal's build and tests need
# (clang among them: scripts/test.sh compiles with it); with --full also
# those of the benchmarks, the sanitizers and the fuzzers (clang's runtimes,
# Google Benchmark) and Debian's chromium (a test opens the
# report's web page in it; without it that test is skipped), which only
# `scripts/test.sh --full` needs. Idempotent: does nothing when all are present.
set -euo pipefail

full=0
case "${1:-}" in
  "") ;;
  --full) full=1 ;;
  *) echo "install_deps.sh: unknown argument '$1' (use --full or nothing)" >&2; exit 2 ;;
esac

packages=(
  build-essential cmake ninja-build pkg-config git
  libopencv-dev libceres-dev libeigen3-dev
  libgflags-dev libgoogle-glog-dev libyaml-cpp-dev
  libgtest-dev libgmock-dev
  libcairo2-dev
  libplplot-dev plplot-driver-cairo
  libdeflate-dev zlib1g-dev
  python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest
  python3-setuptools python3-pip python3-venv python3-yaml
  clang
)
if [ "$full" = 1 ]; then
  # chromium: the report's web page is opened in a real headless browser.
  packages+=(libbenchmark-dev libclang-rt-14-dev chromium)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install_deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
$SUDO apt-get install -y --no-install-recommends "${missing[@]}"
