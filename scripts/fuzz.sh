#!/usr/bin/env bash
# Runs mpshade's libFuzzer targets (tests/fuzz/README.md).
#   scripts/fuzz.sh [SECONDS] [TARGET...]   TARGET: scene shader geometry render (default all)
# Builds build-fuzz (Clang, ASan + UBSan, libFuzzer) if needed, then runs each target for
# SECONDS (default 60), one after another, seeded from
# tests/fuzz/corpus/TARGET; new inputs go to build-fuzz/corpus/TARGET, findings to
# build-fuzz/findings/. Exit status 1 if any target found a crash, leak or timeout.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(scene shader geometry render)

if [ ! -f build-fuzz/build.ninja ]; then
  launcher=()
  if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja "${launcher[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DMPSHADE_FUZZ=ON -DMPSHADE_SANITIZE=ON -DMPSHADE_BUILD_TESTS=OFF -DMPSHADE_BUILD_BENCH=OFF
fi
cmake --build build-fuzz

status=0
mkdir -p build-fuzz/findings
for t in "${targets[@]}"; do
  mkdir -p "build-fuzz/corpus/$t"
  echo "== fuzz_$t for ${seconds}s"
  if ! ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
      "build-fuzz/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=60 \
      -rss_limit_mb=4096 -max_len=65536 -print_final_stats=1 \
      -artifact_prefix="build-fuzz/findings/${t}-" \
      "build-fuzz/corpus/$t" "tests/fuzz/corpus/$t" $(ls -d "tests/fuzz/regressions/$t" 2>/dev/null) \
      2>&1 | tee "build-fuzz/fuzz_$t.log" |
      grep -E "^(#[0-9]+ *(DONE|INITED)|stat::number_of_executed_units|stat::peak_rss|==[0-9]+==ERROR|SUMMARY|.*Test unit written)" | grep -v "slow-unit"; then
    :
  fi
  if grep -E "==ERROR|SUMMARY: |Test unit written|deadly signal" "build-fuzz/fuzz_$t.log" |
      grep -qv "slow-unit"; then
    echo "fuzz_$t: FINDING (see build-fuzz/fuzz_$t.log and build-fuzz/findings/)"
    status=1
  fi
done
exit $status
