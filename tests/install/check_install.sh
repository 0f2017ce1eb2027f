#!/usr/bin/env bash
# check_install.sh BUILD_DIR SOURCE_DIR WORK_DIR: installs the build into WORK_DIR/prefix,
# then configures, builds and runs tests/install/consumer against the installed package
# alone (CMAKE_PREFIX_PATH), and checks the binary and man page are in place.
set -euo pipefail
build="$1" source="$2" work="$3"
rm -rf "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
test -x "$work/prefix/bin/mpshade"
"$work/prefix/bin/mpshade" --version | grep -q "mpshade"
if command -v help2man >/dev/null 2>&1; then
  test -s "$work/prefix/share/man/man1/mpshade.1"
fi
cmake -S "$source/tests/install/consumer" -B "$work/consumer" -G Ninja \
  -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/consumer" >/dev/null
"$work/consumer/consumer" "$source/examples/teapot/scene.json"
