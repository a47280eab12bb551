#!/usr/bin/env bash
# Eleventh session: the direct signal through fewer a-trous passes than the photon map's
# (--denoise-direct-iterations), against the default (every signal all five passes), same build,
# same machine. Phase "kernels": GPU tests, ncu of the denoise kernels on the Sponza walk (separate
# eyes and gather reuse, direct passes 5 and 2). Phase "quality": the quality bench's rows.
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
for phase in "$@"; do
  case $phase in
  tests)
    step gpu_tests 90 .gpu/run.sh .gpu/bin/pvr_gpu_tests ;;
  kernels)
    for stereo in separate gather; do
      for direct in 5 2; do
        step ncu_${stereo}_direct$direct 40 ncu --clock-control none --target-processes all -k regex:"accumulate|variance|atrous|Atrous|remodulate" --launch-skip 50 -c 20 --csv --page raw --metrics $metrics .gpu/run.sh .gpu/bin/photonvr render scenes/dabrovic-sponza.json --backend cuda --photons 512x512 --denoise --denoise-direct-iterations $direct --stereo $stereo --trajectory .scenes/sponza_walk8.traj --out /tmp/ncu --radius 0.15
      done
    done ;;
  quality)
    step quality $((590 - SECONDS)) stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite quality --backend cuda --quality-variants "denoise;denoise, gather reuse;denoise, direct 2 passes;denoise, direct 2 passes, gather reuse" --json $o/quality.json ;;
  nantest)
    step nan_test 120 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter=*ARefiningStillHead* ;;
  nan)
    step nan_test 120 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter=*ARefiningStillHead*
    step initcheck_still 200 compute-sanitizer --target-processes all --tool initcheck --error-exitcode 9 --print-limit 20 .gpu/run.sh .gpu/bin/photonvr render scenes/dabrovic-sponza.json --backend cuda --denoise --stereo gather --eye-size 720x800 --photons 256x256 --radius 0.15 --trajectory .scenes/still120.traj --out /tmp/still/s ;;
  accumulate)
    step ncu_accumulate 40 ncu --clock-control none --target-processes all -k regex:"accumulate" --launch-skip 10 -c 6 --csv --page raw --metrics $metrics .gpu/run.sh .gpu/bin/photonvr render scenes/dabrovic-sponza.json --backend cuda --photons 512x512 --denoise --stereo separate --trajectory .scenes/sponza_walk8.traj --out /tmp/ncu --radius 0.15 ;;
  scenes)
    grep -q H200 $o/gpu.txt || continue
    step scenes $((590 - SECONDS)) stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite scenes --backend cuda --frames 300 --warmup 30 --scene-radius 0.15 --json $o/scenes.json ;;
  esac
done
