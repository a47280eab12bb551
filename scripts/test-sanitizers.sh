#!/usr/bin/env bash
# The whole CPU suite built with AddressSanitizer + UndefinedBehaviorSanitizer (the CUDA backend
# left out: its host code cannot run here anyway). Any report, leaks included, fails a test.
# Usage: scripts/test-sanitizers.sh [BUILD_DIR]   (default build-asan; dependencies from test.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-asan}
flags="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPVR_ENABLE_CUDA=OFF -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
cmake --build "$build" -j"$(nproc)"
export ASAN_OPTIONS=detect_leaks=1:halt_on_error=1:detect_stack_use_after_return=1
export LSAN_OPTIONS=suppressions=$PWD/tests/sanitizers/lsan.supp:print_suppressions=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export PVR_REQUIRE_VULKAN=1
# install_consumer builds a program against the installed library without the sanitizer flags: a
# packaging test, run by test.sh. The viewer's GLX driver (Mesa, loaded and unloaded by GLFW, its
# frames without symbols) leaks 112 bytes at exit: the viewer runs with leak checks off, the
# rest of ASan and UBSan on.
# Lavapipe leaks the same 112 bytes (two 56-byte callocs in a module it unloads, so no symbol to
# suppress) once it has compiled a graphics pipeline: the G-buffer pre-pass's tests and the render
# modes that use it run with leak checks off as well, and so do the soak (its cycle includes the
# pre-pass; it checks its own live heap for growth instead) and the injected faults (their runs
# compile the pre-pass's pipeline before the fault; they check one line and exit code 1).
nolsan='^(viewer_xvfb|cli_modes|soak_cpu|faults_cpu|RasterGBuffer\..*)$'
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" -E "^(install_consumer)\$|$nolsan"
ASAN_OPTIONS=$ASAN_OPTIONS:detect_leaks=0 ctest --test-dir "$build" --output-on-failure -R "$nolsan"
