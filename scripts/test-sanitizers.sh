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
# Sanitized frames take 10-20 times as long: the offscreen loop test keeps its deadline check at a
# display rate they fit (tests/loop_offscreen.sh).
export PVR_LOOP_TEST_REFRESH_HZ=0.25
# install_consumer builds a program against the installed library without the sanitizer flags: a
# packaging test, run by test.sh. The viewer's GLX driver (Mesa, loaded and unloaded by GLFW, its
# frames without symbols) leaks 112 bytes at exit: the viewer runs with leak checks off, the
# rest of ASan and UBSan on.
# Lavapipe (Mesa 22.3.6-1+deb12u2) leaves allocations behind in itself and LLVM, which the Vulkan
# loader unloads when the instance goes: with nothing left to hold them they are reported as
# leaks without symbols to suppress (128 bytes from any instance, 112 more once it has compiled a
# graphics pipeline). Preloaded, the driver is never unloaded and they stay reachable; ASan's
# check that its runtime comes first among the libraries is then off (lavapipe defines no
# allocator). The soak and the injected faults run with leak checks off as before (the soak checks
# its own live heap for growth; the faults check one line and exit code 1).
lavapipe=$(ls /usr/lib/*/libvulkan_lvp.so 2>/dev/null | head -1 || true)
if [ -n "$lavapipe" ]; then
  export LD_PRELOAD=$lavapipe${LD_PRELOAD:+:$LD_PRELOAD}
  ASAN_OPTIONS=$ASAN_OPTIONS:verify_asan_link_order=0
fi
nolsan='^(viewer_xvfb|cli_modes|soak_cpu|faults_cpu)$'
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" -E "^(install_consumer)\$|$nolsan"
ASAN_OPTIONS=$ASAN_OPTIONS:detect_leaks=0 ctest --test-dir "$build" --output-on-failure -R "$nolsan"
