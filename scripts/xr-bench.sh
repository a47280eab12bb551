#!/usr/bin/env bash
# The frame loop's benchmark (issue targets): the default Cornell box, both eyes 1440x1600,
# 512x512 photons, r = 0.05, gather reuse, on the CUDA backend.
#   1. offscreen, no hand-over      - the loop alone
#   2. offscreen, Vulkan hand-over  - CUDA -> Vulkan images without the host, timed on the GPU
#   3. OpenXR (if XR_RUNTIME_JSON)  - the same frames through a runtime's swapchains
# Each writes OUTDIR/<name>.json (per-frame statistics, p50/p99/max) and OUTDIR/<name>.log.
#   usage: xr-bench.sh OUTDIR FRAMES PHOTONVR-COMMAND...
#   e.g.   scripts/xr-bench.sh out/xr 2000 build/photonvr
set -u
outdir=$1
frames=$2
shift 2
mkdir -p "$outdir"
common=(--backend "${PVR_XR_BENCH_BACKEND:-cuda}" --eye-size "${PVR_XR_BENCH_EYE:-1440x1600}" --photons 512x512 --radius 0.05
        --stereo gather --frames "$frames" --warmup 30)
"$@" xr --offscreen --handover none "${common[@]}" --stats "$outdir/offscreen_none.json" >"$outdir/offscreen_none.log" 2>&1
echo "offscreen, no hand-over: exit $?"
"$@" xr --offscreen --handover vulkan "${common[@]}" --stats "$outdir/offscreen_vulkan.json" >"$outdir/offscreen_vulkan.log" 2>&1
echo "offscreen, Vulkan hand-over: exit $?"
if [ -n "${XR_RUNTIME_JSON:-}" ]; then
  "$@" xr "${common[@]}" --stats "$outdir/openxr.json" >"$outdir/openxr.log" 2>&1
  echo "OpenXR ($XR_RUNTIME_JSON): exit $?"
fi
grep -hv "WARN" "$outdir"/*.log
