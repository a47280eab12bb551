#!/usr/bin/env bash
# Faults survived, on the CPU backend and this machine's Vulkan device (lavapipe in CI); the GPU's
# own faults are tests/gpu_faults.sh. Each fault is provoked by PVR_INJECT_FAULT=KIND:N
# (src/pvr/util/fault_injection.h) at every event of a run in turn, until a run outlives the
# last event: each must end with one line on stderr naming the fault, exit code 1, within 60 s.
#   vk-alloc        every Vulkan memory allocation of the G-buffer pre-pass, the viewer's window
#                   and the OpenXR hand-over, failing as VK_ERROR_OUT_OF_DEVICE_MEMORY
#   vk-device-lost  every queue submission of the same runs answering VK_ERROR_DEVICE_LOST
# Also: a corrupt texture (a warning, the render goes on with the constant colour) and a
# malformed PVR_INJECT_FAULT.
#   usage: tests/faults.sh PHOTONVR [FAKE_XR_RUNTIME_JSON]
set -u
exe=$1
xr_json=${2:-}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
small=(--backend cpu --eye-size 32x36 --photons 32x32)

fault_sweep_dir=$out
source "$(dirname "$0")/fault_sweep.sh"
write_three_frames "$out/three.traj"
sweep() {
  local result
  result=$(fault_sweep "$@")
  echo "$result"
  grep -q '^FAIL' <<<"$result" && failures=$((failures + 1))
  return 0
}

raster=("$exe" render cornell "${small[@]}" --primary raster --trajectory "$out/three.traj" --out "$out/r")
sweep "raster pre-pass, 3 frames" vk-alloc "Vulkan: out of memory" "${raster[@]}"
sweep "raster pre-pass, 3 frames" vk-device-lost "VK_ERROR_DEVICE_LOST): the GPU device was lost" "${raster[@]}"
if command -v xvfb-run >/dev/null; then
  # Our own X authority file: xvfb-run's temporary directory for one sometimes fails to go away
  # after the run (lock files of its `xauth remove`), and xvfb-run then exits 5 with its own line.
  view=(xvfb-run -a -f "$out/xauthority" -s "-screen 0 640x480x24" "$exe" view "${small[@]}" --keys 3:Escape)
  sweep "viewer, 3 frames" vk-alloc "Vulkan: out of memory" "${view[@]}"
  sweep "viewer, 3 frames" vk-device-lost "VK_ERROR_DEVICE_LOST" "${view[@]}"
else
  fail "xvfb-run is not installed (package xvfb)"
fi
if [ -n "$xr_json" ]; then
  xr=(env XR_RUNTIME_JSON="$xr_json" PVR_FAKE_XR=ok "$exe" xr --backend cpu --photons 16x16 --frames 4 --stats "")
  sweep "OpenXR session, 4 frames" vk-alloc "Vulkan: out of memory" "${xr[@]}"
  sweep "OpenXR session, 4 frames" vk-device-lost "VK_ERROR_DEVICE_LOST" "${xr[@]}"
fi

# A corrupt texture: the render goes on, the material keeps its constant colour, one warning.
"$exe" render cornell --backend cpu --eye-size 16x16 --photons 8x8 --out "$out/tex" >/dev/null 2>&1
head -c 300 "$out/tex_left.png" >"$out/corrupt.png"
write_textured_quad "$out" corrupt corrupt.png
"$exe" render "$out/corrupt.json" "${small[@]}" --out "$out/c" >/dev/null 2>"$out/stderr"
rc=$?
if [ $rc -ne 0 ] || [ "$(grep -c . "$out/stderr")" -ne 1 ] ||
   ! grep -q "warning: texture '.*corrupt.png' cannot be read: .*; its material keeps its constant colour" "$out/stderr" ||
   [ ! -s "$out/c_left.png" ]; then
  fail "corrupt texture: exit code $rc, stderr: $(cat "$out/stderr")"
else
  echo "ok   corrupt texture: $(cat "$out/stderr")"
fi

# A malformed fault plan is refused before anything runs.
before=$failures
for bad in "gpu-alloc" "gpu-alloc:0" "gpu-alloc:x" "disk-full:1" "vk-alloc:-1" "vk-alloc:+2"; do
  PVR_INJECT_FAULT=$bad "$exe" render cornell "${small[@]}" --out "$out/b" >/dev/null 2>"$out/stderr"
  rc=$?
  if [ $rc -ne 1 ] || [ "$(grep -c . "$out/stderr")" -ne 1 ] || ! grep -q "PVR_INJECT_FAULT must be KIND:N" "$out/stderr"; then
    fail "PVR_INJECT_FAULT=$bad: exit code $rc, stderr: $(cat "$out/stderr")"
  fi
done
[ $failures -eq $before ] && echo "ok   malformed PVR_INJECT_FAULT values refused with one line"

[ $failures -eq 0 ] && echo "all fault cases passed" || echo "$failures fault case(s) failed"
exit $((failures > 0))
