#!/usr/bin/env bash
# Eighth session, second call: the history read with its loads in flight together (Catmull-Rom and
# bilinear, ncu on the Sponza walk), gather's right eye shading a list of the pixels it does not
# reuse (ncu on Sibenik; bench --suite scenes), the GPU suite, memcheck, then the quality bench.
set -u
cd "$(dirname "$0")/.."
tar -C .gpu -xJf .gpu/bin.tar.xz
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
export PVR_SCENES=$PWD/.scenes PVR_REQUIRE_VULKAN=1
o=$OUT/r; mkdir -p $o
pack() { tar -C $OUT -czf $OUT/results.tgz r; }
trap pack EXIT
nvidia-smi --query-gpu=name,driver_version --format=csv > $o/gpu.txt 2>&1
step() { local name=$1 t=$2; shift 2; local s=$SECONDS; timeout $t "$@" > $o/$name.txt 2>&1; echo "$name rc=$? $((SECONDS-s)) s" | tee -a $o/steps.txt; pack; }
if [ "${1:-}" = quality ]; then  # the second call, on the warm machine
  o=$OUT/q; mkdir -p $o; pack() { tar -C $OUT -czf $OUT/results.tgz q; }
  step quality $((${DEVICE_LIMIT:-600} - 15 - SECONDS)) stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite quality --backend cuda --quality-variants "denoise;denoise, gather reuse;denoise, bilinear history;denoise, 4 passes;denoise, 3 passes" --json $o/quality.json
  exit 0
fi
metrics=gpu__time_duration.sum,launch__registers_per_thread,dram__bytes.sum,sm__throughput.avg.pct_of_peak_sustained_elapsed
for h in catmull-rom bilinear; do
  step ncu_$h 60 ncu --clock-control none --target-processes all -k regex:"accumulateKernel" --launch-skip 10 -c 4 --csv --page raw --metrics $metrics .gpu/run.sh .gpu/bin/photonvr render scenes/dabrovic-sponza.json --backend cuda --photons 512x512 --denoise --denoise-history $h --trajectory .scenes/sponza_walk8.traj --out /tmp/ncu --radius 0.15
done
step ncu_right_eye 60 ncu --clock-control none --target-processes all -k regex:"Kernel|estimate" --csv --page raw --metrics $metrics .gpu/run.sh .gpu/bin/photonvr render scenes/sibenik.json --backend cuda --photons 512x512 --stereo gather --out /tmp/ncu_s --radius 0.15
step gpu_tests 150 .gpu/run.sh .gpu/bin/pvr_gpu_tests
small=(--backend cuda --eye-size 320x352 --photons 128x128 --out /tmp/pvr_sanitized)
step memcheck_sponza_gather 90 compute-sanitizer --target-processes all --tool memcheck --error-exitcode 9 .gpu/run.sh .gpu/bin/photonvr render scenes/dabrovic-sponza.json "${small[@]}" --stereo gather --radius 0.15 --denoise --trajectory .scenes/sponza_walk8.traj
step memcheck_cornell_separate 60 compute-sanitizer --target-processes all --tool memcheck --error-exitcode 9 .gpu/run.sh .gpu/bin/photonvr render cornell "${small[@]}" --denoise --trajectory .scenes/cornell_sway8.traj
step scenes 150 stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite scenes --backend cuda --frames 300 --warmup 30 --scene-radius 0.15 --json $o/scenes.json
