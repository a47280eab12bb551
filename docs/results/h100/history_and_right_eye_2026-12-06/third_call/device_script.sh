#!/usr/bin/env bash
# Eighth session, third call: the 12-tap Catmull-Rom read with one moments load a tap (ncu against
# bilinear, Sponza walk), the GPU suite, then the quality bench's history and pass-count rows.
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
metrics=gpu__time_duration.sum,launch__registers_per_thread,dram__bytes.sum,sm__throughput.avg.pct_of_peak_sustained_elapsed,l1tex__t_sectors.sum
for h in catmull-rom bilinear; do
  step ncu_$h 45 ncu --clock-control none --target-processes all -k regex:"accumulateKernel|varianceKernel" --launch-skip 20 -c 4 --csv --page raw --metrics $metrics .gpu/run.sh .gpu/bin/photonvr render scenes/dabrovic-sponza.json --backend cuda --photons 512x512 --denoise --denoise-history $h --trajectory .scenes/sponza_walk8.traj --out /tmp/ncu --radius 0.15
done
step gpu_tests 60 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter='*Denois*:*StereoReuse*'
step quality $((${DEVICE_LIMIT:-600} - 15 - SECONDS)) stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite quality --backend cuda --quality-variants "denoise;denoise, bilinear history;denoise, 4 passes;denoise, 3 passes" --json $o/quality.json
