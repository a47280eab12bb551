#!/usr/bin/env bash
# ThreadSanitizer over photonvr's CPU-parallel code: built with -fsanitize=thread and its parallel
# loops on std::threads (PVR_PARALLEL_STD_THREADS: TSan cannot see the synchronisation inside
# Debian's uninstrumented TBB and would report every hand-over of work; see docs/reliability.md).
# Runs the unit tests (each parallel stage: photon tracing, both photon maps and the kd-tree's
# parallel build, the eye passes, stereo reuse, foveation, TAA, the denoiser, the reference, the
# surface cache), the offscreen frame loop and the soak. Any report fails a test.
# Usage: scripts/test-tsan.sh [BUILD_DIR [CTEST_ARGS...]]   (default build-tsan; dependencies from test.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-tsan}
shift || true
flags="-fsanitize=thread -fno-omit-frame-pointer"
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPVR_ENABLE_CUDA=OFF -DPVR_PARALLEL_STD_THREADS=ON \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=thread" >/dev/null
cmake --build "$build" -j"$(nproc)"
# halt_on_error: a report fails the test. ignore_noninstrumented_modules: Mesa's and Embree's own
# threads (not built with TSan) are theirs to check.
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:ignore_noninstrumented_modules=1:suppressions=$PWD/tests/sanitizers/tsan.supp"
export PVR_REQUIRE_VULKAN=1
# Sanitized frames take 10-20 times as long: the offscreen loop test keeps its deadline check at a
# display rate they fit (tests/loop_offscreen.sh).
export PVR_LOOP_TEST_REFRESH_HZ=0.25
# Left out: what runs no photonvr threads (packaging, the fuzz inputs' replay, the viewer: GLFW's
# X11 under Xvfb), and in CI (PVR_TSAN_QUICK=1) the ten tests that take over a minute each under
# TSan (25 of its 50 minutes on 2 cores); they cover the same loops on more frames, and passed
# under TSan in full runs (docs/reliability.md).
skip='install_consumer|viewer_xvfb|fuzz_replay_.*'
if [ "${PVR_TSAN_QUICK:-0}" = 1 ]; then
  skip+='|bench_tables_cpu|bench_stereo_cpu|bench_foveation_cpu|bench_scenes_cpu|cli_bad_input|faults_cpu'
  skip+='|ProgressiveReference\..*|DenoiseFrames\.(AStillHeadRefinesAndAMoveDoesNotPop|TaaOfAMovingHeadLeavesTheLightsEdgeAlone|TheCornellBoxComesCloserToItsReference)'
  skip+='|SurfaceCache\.FramesKeepThePerPixelErrorAgainstTheReference'
fi
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" -L cpu -E "^($skip)\$" "$@"
