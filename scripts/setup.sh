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

# The sanitized suite. LeakSanitizer's own stop-the-world tracer now and then crashes as a
# process exits ("Tracer caught signal 11", then "LeakSanitizer has encountered a fatal
# error"), after the test has passed and before any leak is looked for: a known fault of the
# sanitizer runtime (google/sanitizers issues 1170 and 1353), not of the code under test.
# When every failed test shows that signature, those tests alone run once more; any other
# failure fails at once.
sanitized_tests() {
  local log=build-sanitize/Testing/ctest-sanitize.log
  mkdir -p build-sanitize/Testing
  if ctest --test-dir build-sanitize --output-on-failure -j "$(nproc)" 2>&1 | tee "$log"; then
    return 0
  fi
  local failed crashes
  failed=$(grep -c . build-sanitize/Testing/Temporary/LastTestsFailed.log || true)
  crashes=$(grep -c "LeakSanitizer has encountered a fatal error" "$log" || true)
  if [ "$failed" -eq 0 ] || [ "$crashes" -lt "$failed" ]; then
    echo "sanitized tests: $failed failed, $crashes with the LeakSanitizer tracer's crash" >&2
    return 1
  fi
  echo "sanitized tests: the $failed failed test(s) all ended in LeakSanitizer's tracer crash; running them once more" >&2
  ctest --test-dir build-sanitize --output-on-failure --rerun-failed
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
    export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
    sanitized_tests
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
