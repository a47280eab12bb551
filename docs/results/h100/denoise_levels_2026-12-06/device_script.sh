#!/usr/bin/env bash
# Tenth session: the denoiser's later levels in half precision and a reusing right eye's history
# by reference (this build, 818d059) against photonvr_base = 538b6a4 (main before them). Same machine:
# the GPU tests; the denoise kernels of both on the Sponza walk, separate eyes and gather reuse
# (ncu); memcheck and initcheck on the denoiser's paths; the quality bench's denoise rows as far
# as the call's time goes (the session's device time was nearly spent on machines that did not start).
set -u
cd "$(dirname "$0")/../../../.."
tar -C .gpu -xJf .gpu/bin.tar.xz
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
export PVR_SCENES=$PWD/.scenes PVR_REQUIRE_VULKAN=1
o=$OUT/r; mkdir -p $o
pack() { tar -C $OUT -czf $OUT/results.tgz r; }
trap pack EXIT
nvidia-smi --query-gpu=name,driver_version --format=csv > $o/gpu.txt 2>&1
step() { local name=$1 t=$2; shift 2; local s=$SECONDS; timeout $t "$@" > $o/$name.txt 2>&1; echo "$name rc=$? $((SECONDS-s)) s" | tee -a $o/steps.txt; pack; }
metrics=gpu__time_duration.sum,launch__registers_per_thread,dram__bytes.sum,sm__throughput.avg.pct_of_peak_sustained_elapsed
step gpu_tests 60 .gpu/run.sh .gpu/bin/pvr_gpu_tests
for b in photonvr_base photonvr; do
  for stereo in separate gather; do
    step ncu_${b}_$stereo 30 ncu --clock-control none --target-processes all -k regex:"accumulate|variance|atrous|Atrous|remodulate" --launch-skip 50 -c 20 --csv --page raw --metrics $metrics .gpu/run.sh .gpu/bin/$b render scenes/dabrovic-sponza.json --backend cuda --photons 512x512 --denoise --stereo $stereo --trajectory .scenes/sponza_walk8.traj --out /tmp/ncu_$b --radius 0.15
  done
done
# The denoiser's changed paths under compute-sanitizer.
small=(--backend cuda --eye-size 320x352 --photons 128x128 --out /tmp/pvr_sanitized --trajectory tests/data/gaze_pursuit.traj)
for tool in memcheck initcheck; do
  step ${tool}_denoised 30 compute-sanitizer --target-processes all --tool $tool --error-exitcode 9 .gpu/run.sh .gpu/bin/photonvr render cornell "${small[@]}" --denoise --photon-batches 4 --taa --stereo gather --boundary clipped
  step ${tool}_listed 30 compute-sanitizer --target-processes all --tool $tool --error-exitcode 9 .gpu/run.sh .gpu/bin/photonvr render cornell "${small[@]}" --primary raster --stereo gather --denoise
done
step quality $((${DEVICE_LIMIT:-290} - 5 - SECONDS)) stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite quality --backend cuda --quality-variants "denoise;denoise, gather reuse" --json $o/quality.json
