#!/usr/bin/env bash
# photonvr as a library: installs the build into a temporary prefix, configures and builds
# examples/consumer against it with find_package(photonvr), and runs it (CPU backend where no GPU).
set -eu
build=$1
source=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log"
test -f "$work/prefix/lib/cmake/photonvr/photonvrConfig.cmake" || { echo "FAIL: no photonvrConfig.cmake installed"; exit 1; }
test -f "$work/prefix/include/pvr/photonvr.h" || { echo "FAIL: the public header is not installed"; exit 1; }
cmake -S "$source/examples/consumer" -B "$work/consumer" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" >"$work/configure.log" || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/consumer" -j2 >"$work/build.log" || { tail -40 "$work/build.log"; exit 1; }
"$work/consumer/photonvr_consumer"
