#!/usr/bin/env bash
# One-command setup for a fresh Debian (bookworm) machine:
#   tools/setup.sh demo   install missing packages, build, render the default scene with denoising
#   tools/setup.sh test   install missing packages, build, run the whole test suite (CTest),
#                         then the sanitizer step below (what .ci/run runs)
#   tools/setup.sh build  install missing packages and build only
#   tools/setup.sh bench  also install the renderer benchmark's peer (embree-tools), build,
#                         run build/bench/bench_render (about 3 minutes after the build)
#   tools/setup.sh sanitize  build chorus, the fuzzer and the input-facing unit tests with
#                         AddressSanitizer and UBSan in build-asan/ (-O0) and run them, the fuzz
#                         regression inputs included (docs/fuzzing.md)
# Environment: BUILD_DIR (default build; build-asan for sanitize), JOBS (default: number of
# cores), CI=true adds -Werror.
set -euo pipefail
cd "$(dirname "$0")/.."

mode=${1:-demo}
case "$mode" in
  demo | test | build | bench | sanitize) ;;
  *)
    echo "usage: tools/setup.sh [demo|test|build|bench|sanitize]" >&2
    exit 2
    ;;
esac
build_dir=${BUILD_DIR:-build}
[ "$mode" = sanitize ] && build_dir=${BUILD_DIR:-build-asan}
jobs=${JOBS:-$(nproc)}

packages=(g++ cmake make pkg-config libembree-dev libtinygltf-dev libopenexr-dev libtbb-dev
          libgtest-dev libeigen3-dev libcli11-dev libstb-dev nlohmann-json3-dev zlib1g-dev)
# The report test loads report.html in a real browser.
[ "$mode" = test ] && packages+=(chromium)
# The renderer benchmark runs Embree's own tutorial path tracer as its peer.
[ "$mode" = bench ] && packages+=(embree-tools)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo=sudo
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

werror=OFF
[ "${CI:-}" = "true" ] && werror=ON

# A CHORUS_ASAN build configures only the sanitizer's tests (tests/CMakeLists.txt); of the tools
# only chorus and the fuzzer, which they run, are built. -O0: it compiles in two thirds of -O1's
# time and its tests run about as long (docs/fuzzing.md), and nothing is optimised away.
sanitizer_step() {
  local dir=${SANITIZE_BUILD_DIR:-build-asan}
  echo "setup: sanitizer build in $dir"
  cmake -S . -B "$dir" -DCHORUS_ASAN=ON -DCMAKE_BUILD_TYPE=Sanitize \
    -DCMAKE_CXX_FLAGS_SANITIZE="-O0 -DNDEBUG" -DCHORUS_WERROR=$werror > /dev/null
  cmake --build "$dir" -j "$jobs" --target sanitizer_tests
  ctest --test-dir "$dir" --output-on-failure -j "$jobs"
}

if [ "$mode" = sanitize ]; then
  SANITIZE_BUILD_DIR=$build_dir sanitizer_step
  exit 0
fi
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCHORUS_WERROR=$werror > /dev/null
cmake --build "$build_dir" -j "$jobs"

case "$mode" in
  build) ;;
  test)
    ctest --test-dir "$build_dir" --output-on-failure -j "$jobs"
    sanitizer_step
    ;;
  bench)
    "$build_dir"/bench/bench_render
    ;;
  demo)
    out=out/cornell-box
    "$build_dir"/chorus render scenes/cornell-box.gltf --out "$out"
    echo "setup: wrote"
    ls -l "$out"
    ;;
esac
