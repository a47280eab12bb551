#!/usr/bin/env bash
# Fifth session, fifth call: the final denoiser build: GPU suite, sanitizers, ncu split, quality bench (Cornell, Sponza).
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
step() { local name=$1 t=$2; shift 2; local s=$SECONDS; timeout $t "$@" > $o/$name.txt 2>&1; echo "$name rc=$? $((SECONDS-s)) s" | tee -a $o/steps.txt; }
step gpu_tests 100 .gpu/run.sh .gpu/bin/pvr_gpu_tests
small=(--backend cuda --eye-size 320x352 --photons 128x128 --out /tmp/pvr_sanitized --denoise --trajectory .scenes/cornell_sway8.traj)
for mode in separate gather; do
  step memcheck_$mode 60 compute-sanitizer --target-processes all --tool memcheck --error-exitcode 9 .gpu/run.sh .gpu/bin/photonvr render cornell "${small[@]}" --stereo $mode
  step racecheck_$mode 90 compute-sanitizer --target-processes all --tool racecheck --error-exitcode 9 .gpu/run.sh .gpu/bin/photonvr render cornell "${small[@]}" --stereo $mode
done
step initcheck 60 compute-sanitizer --target-processes all --tool initcheck --error-exitcode 9 .gpu/run.sh .gpu/bin/photonvr render cornell "${small[@]}" --stereo gather
profile() {
  local name=$1 scene=$2 traj=$3; shift 3
  step ncu_$name 90 ncu --clock-control none --target-processes all -k regex:"accumulateKernel|varianceKernel|atrous" --launch-skip 70 -c 14 -o $o/ncu_$name .gpu/run.sh .gpu/bin/photonvr render $scene --backend cuda --photons 512x512 --denoise --trajectory $traj --out /tmp/ncu_$name "$@"
  ncu -i $o/ncu_$name.ncu-rep --page details --print-units base > $o/ncu_$name.txt 2>&1; rm -f $o/ncu_$name.ncu-rep
}
profile cornell_gather cornell .scenes/cornell_sway8.traj --stereo gather
profile sponza_separate scenes/dabrovic-sponza.json .scenes/sponza_walk8.traj --radius 0.15
profile sponza_gather scenes/dabrovic-sponza.json .scenes/sponza_walk8.traj --radius 0.15 --stereo gather
step quality 360 stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite quality --backend cuda --quality-variants "denoise;denoise, gather reuse" --json $o/quality.json
