#!/usr/bin/env bash
# Eighth session, first call: main's build (d1a51c4 + --denoise-history) on the GPU: the suite,
# memcheck, the accumulation with Catmull-Rom vs bilinear history reads (ncu, Sponza walk), and
# bench --suite scenes (recordShadowsKernel went from ~132 to ~163 registers with d1a51c4).
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
for h in catmull-rom bilinear; do
  step ncu_$h 70 ncu --clock-control none --target-processes all -k regex:"accumulateKernel|varianceKernel|atrous|remodulate" --launch-skip 70 -c 16 --csv --page raw --metrics gpu__time_duration.sum,launch__registers_per_thread,dram__bytes.sum,sm__throughput.avg.pct_of_peak_sustained_elapsed .gpu/run.sh .gpu/bin/photonvr render scenes/dabrovic-sponza.json --backend cuda --photons 512x512 --denoise --denoise-history $h --trajectory .scenes/sponza_walk8.traj --out /tmp/ncu --radius 0.15
done
step gpu_tests 120 .gpu/run.sh .gpu/bin/pvr_gpu_tests
small=(--backend cuda --eye-size 320x352 --photons 128x128 --out /tmp/pvr_sanitized --denoise --trajectory .scenes/cornell_sway8.traj)
step memcheck_gather 60 compute-sanitizer --target-processes all --tool memcheck --error-exitcode 9 .gpu/run.sh .gpu/bin/photonvr render cornell "${small[@]}" --stereo gather
step memcheck_separate 60 compute-sanitizer --target-processes all --tool memcheck --error-exitcode 9 .gpu/run.sh .gpu/bin/photonvr render cornell "${small[@]}" --stereo separate
step ncu_shadows 70 ncu --clock-control none --target-processes all -k regex:"recordShadows|EyeKernel|eyeKernel|Eye" -c 30 --csv --page raw --metrics gpu__time_duration.sum,launch__registers_per_thread,launch__occupancy_limit_registers .gpu/run.sh .gpu/bin/photonvr render scenes/sibenik.json --backend cuda --photons 512x512 --stereo gather --out /tmp/ncu_s --radius 0.15
step scenes $((${DEVICE_LIMIT:-600} - 20 - SECONDS)) stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite scenes --backend cuda --frames 300 --warmup 30 --scene-radius 0.15 --json $o/scenes.json
