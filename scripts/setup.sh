#!/usr/bin/env bash
# mpshade set-up: installs the Debian packages mpshade needs (only those missing), builds,
# and then does one job.
#
#   scripts/setup.sh demo       install, build, render the vase example to out/vase/
#   scripts/setup.sh test       install, build (warnings are errors), run the whole test suite
#   scripts/setup.sh sanitize   the same under AddressSanitizer + UndefinedBehaviorSanitizer
#   scripts/setup.sh fuzz [S]   each libFuzzer target for S seconds (default 30), ASan + UBSan
#   scripts/setup.sh build      install and build only
#
# Idempotent: a second run installs nothing and rebuilds only what changed.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

PACKAGES=(
  cmake ninja-build g++ ccache pkg-config
  libosd-dev libglm-dev libopenimageio-dev openimageio-tools libopenexr-dev libpng-dev
  libembree-dev libtbb-dev
  libgtest-dev googletest libbenchmark-dev libcli11-dev nlohmann-json3-dev libfmt-dev libxxhash-dev
  gnuplot-nox help2man
  slurm-wlm munge
)
# The fuzz targets only: Clang and its libFuzzer runtime.
FUZZ_PACKAGES=(clang libclang-rt-14-dev)

install_packages() {
  local missing=()
  for p in "${PACKAGES[@]}" "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    return
  fi
  echo "mpshade setup: installing ${missing[*]}" >&2
  local sudo=""
  if [ "$(id -u)" != 0 ]; then sudo="sudo"; fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# build DIR [cmake options...]
build() {
  local dir="$1"; shift
  local launcher=()
  if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  cmake -S . -B "$dir" -G Ninja "${launcher[@]}" "$@" >/dev/null
  cmake --build "$dir" -j "$(nproc)"
}

job="${1:-}"
case "$job" in
  demo)
    install_packages
    build build
    ./build/app/mpshade render examples/vase/scene.json --out out/vase --frames 0:2
    echo "mpshade: wrote out/vase/frame_0000.{exr,png}, frame_0001.{exr,png} and stats.json"
    ;;
  test)
    install_packages
    build build -DMPSHADE_WERROR=ON
    ctest --test-dir build --output-on-failure -j "$(nproc)"
    ;;
  sanitize)
    install_packages
    build build-sanitize -DMPSHADE_WERROR=ON -DMPSHADE_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMPSHADE_BUILD_BENCH=OFF
    ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      ctest --test-dir build-sanitize --output-on-failure -j "$(nproc)"
    ;;
  fuzz)
    install_packages "${FUZZ_PACKAGES[@]}"
    bash scripts/fuzz.sh "${2:-30}"
    ;;
  build)
    install_packages
    build build
    ;;
  *)
    echo "usage: scripts/setup.sh demo|test|sanitize|fuzz [SECONDS]|build" >&2
    exit 2
    ;;
esac
