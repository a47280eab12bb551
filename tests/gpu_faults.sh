#!/usr/bin/env bash
# Faults survived on the CUDA backend (the CPU and Vulkan ones are tests/faults.sh). Each fault is
# provoked by PVR_INJECT_FAULT=KIND:N (src/pvr/util/fault_injection.h) at every event of a run in
# turn, until a run outlives the last event; each must end with one line on stderr naming the
# fault, exit code 1, within 60 s (no hang):
#   gpu-alloc       every CUDA allocation of runs that between them reach every allocation site
#                   (photon buffers, maps, eye buffers, reuse, TAA, the denoiser, the rolling map,
#                   the surface cache, foveation, kd-tree/kNN, textures, the pre-pass's import,
#                   the offscreen loop's hand-over), failing as cudaErrorMemoryAllocation
#   gpu-fault       every eye pass of those runs starting with a kernel that traps: the context
#                   is lost (cudaErrorLaunchFailure, as after a kernel fault or an Xid)
#   vk-device-lost  every Vulkan submission of the pre-pass that shares memory with CUDA
# Prints the allocation sites each sweep reached. Exits 77 (skipped) where no CUDA GPU is present.
#   usage: tests/gpu_faults.sh PHOTONVR DATA_DIR
set -u
exe=$1
data=$2
top=$(mktemp -d)
trap 'rm -rf "$top"' EXIT
out=$top
if ! "$exe" render --backend cuda --eye-size 8x8 --photons 8x8 --out "$out/probe" >/dev/null 2>"$out/probe.err"; then
  if grep -q "^photonvr: error: --backend cuda: no" "$out/probe.err"; then
    echo "no CUDA GPU: skipped ($(cat "$out/probe.err"))"
    exit 77
  fi
  echo "FAIL: the CUDA probe render failed: $(cat "$out/probe.err")"
  exit 1
fi
fault_sweep_dir=$top
source "$(dirname "$0")/fault_sweep.sh"
small=(--backend cuda --eye-size 96x104 --photons 64x64)
# A textured quad in the Cornell box (its texture: a PNG photonvr renders), so that textures are
# uploaded without test models installed.
"$exe" render cornell --backend cpu --eye-size 16x16 --photons 8x8 --out "$out/tex" >/dev/null 2>&1
write_textured_quad "$out" textured tex_left.png
write_three_frames "$out/three.traj"
traj=(--trajectory "$out/three.traj")

# Each sweep runs in the background (the GPU and 16 cores take them at once) and prints its
# result as soon as it ends, so a run cut short still shows what ended.

runs=(
  "scatter+TAA|render cornell-caustics ${small[*]} --stereo scatter --kernel shared --taa ${traj[*]} --out $out/a"
  "denoised+rolling|render cornell ${small[*]} --denoise --photon-batches 4 --stereo gather ${traj[*]} --out $out/b"
  "textures+cache|render $out/textured.json ${small[*]} --density cache --stereo gather --out $out/c"
  "foveated+sorted|render cornell ${small[*]} --foveated --stereo gather --kernel sorted ${traj[*]} --out $out/d"
  "kd-tree+kNN|render cornell ${small[*]} --map kdtree --estimator knn --kernel single --out $out/e"
  "pre-pass+path|render cornell-caustics ${small[*]} --primary raster --effects path --stereo gather ${traj[*]} --out $out/f"
  "offscreen loop|xr --offscreen ${small[*]} --frames 6 --stats $out/g.json"
)
for entry in "${runs[@]}"; do
  name=${entry%%|*}
  # The two sweeps of a run at once: each writes its own images and statistics.
  read -r -a alloc <<<"${entry#*|}"
  read -r -a fault <<<"$(sed -e "s|--out $out/|--out $out/fault-|" -e "s|--stats $out/|--stats $out/fault-|" <<<"${entry#*|}")"
  fault_sweep "$name" gpu-alloc "GPU out of memory" "$exe" "${alloc[@]}" 2>&1 | tee -a "$top/results" &
  fault_sweep "$name" gpu-fault "the GPU device was lost" "$exe" "${fault[@]}" 2>&1 | tee -a "$top/results" &
done
read -r -a args <<<"render cornell-caustics ${small[*]} --primary raster --stereo gather ${traj[*]} --out $out/h"
fault_sweep "pre-pass shared with CUDA" vk-device-lost "VK_ERROR_DEVICE_LOST" "$exe" "${args[@]}" 2>&1 | tee -a "$top/results" &
fault_sweep "pre-pass shared with CUDA" vk-alloc "Vulkan: out of memory" "$exe" "${args[@]}" 2>&1 | tee -a "$top/results" &
wait
failures=$(grep -c '^FAIL' "$top/results")
[ "$failures" -eq 0 ] && echo "all GPU fault cases passed" || echo "$failures GPU fault case(s) failed"
exit $((failures > 0))
