#!/usr/bin/env bash
# check_install.sh BUILD_DIR SOURCE_DIR WORK_DIR: installs the build into WORK_DIR/prefix,
# then configures, builds and runs tests/install/consumer against the installed package
# alone (CMAKE_PREFIX_PATH), and checks the binary, its OpenImageIO module and the man page
# are in place: the installed binary renders a frame and reads it back through the module.
set -euo pipefail
build="$1" source="$2" work="$3"
rm -rf "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
test -x "$work/prefix/bin/mpshade"
"$work/prefix/bin/mpshade" --version | grep -q "mpshade"
# The module is found beside the installed binary (lib/mpshade), not in the build tree:
# `compare` reads both images through it.
"$work/prefix/bin/mpshade" render "$source/examples/vase/scene.json" --frames 0:1 --size 64x36 \
  --no-store --quiet --out "$work/frames" >/dev/null
"$work/prefix/bin/mpshade" compare "$work/frames/frame_0000.exr" "$work/frames/frame_0000.png" \
  >/dev/null
if command -v help2man >/dev/null 2>&1; then
  test -s "$work/prefix/share/man/man1/mpshade.1"
fi
cmake -S "$source/tests/install/consumer" -B "$work/consumer" -G Ninja \
  -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/consumer" >/dev/null
"$work/consumer/consumer" "$source/examples/teapot/scene.json"
