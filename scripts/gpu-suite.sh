#!/usr/bin/env bash
# The GPU suite, run on a GPU machine from a bundle of this build (made here by
#   ../shared/gpu/bundle.sh .gpu build/photonvr build/tests/pvr_gpu_tests):
# the CUDA-vs-CPU tests, every render mode, the GPU bad-input cases and injected faults (out of
# memory at every allocation, a lost device) through the executable, and
# compute-sanitizer (memcheck, racecheck, synccheck, initcheck) on representative render modes
# (TAA with scatter reuse, foveated gather, denoised with a rolling photon map, the surface cache,
# the G-buffer pre-pass at the path level, and gather reuse over the pre-pass's first hits).
#   usage: scripts/gpu-suite.sh BUNDLE_DIR LOG_DIR [--no-sanitizer]
# Prints one line per part and exits non-zero if any part failed; the logs go to LOG_DIR.
set -u
bundle=$(cd "$1" && pwd)
log=$2
mkdir -p "$log"
cd "$(dirname "$0")/.."
# A plain executable path for the test scripts: the bundle's runner with its libraries.
cat >"$bundle/photonvr" <<WRAP
#!/usr/bin/env bash
exec "$bundle/run.sh" "$bundle/bin/photonvr" "\$@"
WRAP
chmod +x "$bundle/photonvr"
failures=0
part() {  # name, command...
  local name=$1
  shift
  local start=$SECONDS
  "$@" >"$log/$name.txt" 2>&1
  local rc=$?
  echo "$name: $([ $rc -eq 0 ] && echo ok || echo "FAILED (exit $rc)") in $((SECONDS - start)) s"
  [ $rc -eq 0 ] || failures=$((failures + 1))
}
part gpu_tests "$bundle/run.sh" "$bundle/bin/pvr_gpu_tests"
part cli_modes_cuda bash tests/cli_modes.sh "$bundle/photonvr" tests/data cuda
part gpu_bad_input bash tests/gpu_bad_input.sh "$bundle/photonvr"
part gpu_faults bash tests/gpu_faults.sh "$bundle/photonvr" tests/data
if [ "${3:-}" != --no-sanitizer ] && command -v compute-sanitizer >/dev/null; then
  small=(--backend cuda --eye-size 320x352 --photons 128x128 --out /tmp/pvr_sanitized)
  for tool in memcheck racecheck synccheck initcheck; do
    part "sanitizer_$tool" compute-sanitizer --tool "$tool" --error-exitcode 9 \
      "$bundle/photonvr" render cornell-caustics "${small[@]}" --stereo scatter --kernel shared --taa \
      --trajectory tests/data/gaze_pursuit.traj
    part "sanitizer_${tool}_foveated" compute-sanitizer --tool "$tool" --error-exitcode 9 \
      "$bundle/photonvr" render cornell "${small[@]}" --foveated --stereo gather --taa --kernel sorted \
      --trajectory tests/data/gaze_pursuit.traj
    part "sanitizer_${tool}_denoised" compute-sanitizer --tool "$tool" --error-exitcode 9 \
      "$bundle/photonvr" render cornell "${small[@]}" --denoise --photon-batches 4 --taa --stereo gather \
      --boundary clipped --trajectory tests/data/gaze_pursuit.traj
    part "sanitizer_${tool}_cached" compute-sanitizer --tool "$tool" --error-exitcode 9 \
      "$bundle/photonvr" render cornell-caustics "${small[@]}" --density cache --stereo gather --denoise \
      --trajectory tests/data/gaze_pursuit.traj
    # The G-buffer pre-pass (Vulkan memory CUDA imported; needs the Vulkan loader) and the path level.
    part "sanitizer_${tool}_raster" compute-sanitizer --tool "$tool" --error-exitcode 9 \
      "$bundle/photonvr" render cornell-caustics "${small[@]}" --primary raster --effects path --stereo gather \
      --trajectory tests/data/gaze_pursuit.traj
    # Gather reuse over the pre-pass's first hits: the right eye's reuse decisions, then its list of
    # the pixels it shades itself (eye_pass.cu's listed path), denoised.
    part "sanitizer_${tool}_listed" compute-sanitizer --tool "$tool" --error-exitcode 9 \
      "$bundle/photonvr" render cornell "${small[@]}" --primary raster --stereo gather --denoise \
      --trajectory tests/data/gaze_pursuit.traj
  done
fi
echo "$failures part(s) failed"
[ $failures -eq 0 ]
