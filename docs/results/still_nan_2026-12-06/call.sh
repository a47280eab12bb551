#!/usr/bin/env bash
# Twelfth session: the still head's non-finite pixels under gather reuse (the quality bench's
# Sponza row after 5 s), GPU tests, the accumulation kernel after its register fix, the quality
# bench's denoise rows and the scenes suite (issues 13 and 14 name the H200).
# Run from the repository root with carry [".gpu", ".gl", ".scenes"]: call.sh PHASE...
set -u
source scripts/device-env.sh
metrics=gpu__time_duration.sum,launch__registers_per_thread,dram__bytes.sum,sm__throughput.avg.pct_of_peak_sustained_elapsed
for phase in "$@"; do
  case $phase in
  nantest)
    step nan_test 150 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter=*ARefiningStillHead* ;;
  nan2)
    step nan_twice 100 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter=*ARefiningStillHead* --gtest_repeat=2 ;;
  nanrepeat)
    step nan_repeat 120 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter=*ARefiningStillHead* --gtest_repeat=3
    step nan_blocking 120 env CUDA_LAUNCH_BLOCKING=1 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter=*ARefiningStillHead* --gtest_repeat=3 ;;
  tests)
    step gpu_tests 200 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter=-*ARefiningStillHead* ;;
  accumulate)
    step ncu_accumulate 60 ncu --clock-control none --target-processes all -k regex:"accumulate" --launch-skip 10 -c 6 --csv --page raw --metrics $metrics .gpu/run.sh .gpu/bin/photonvr render scenes/dabrovic-sponza.json --backend cuda --photons 512x512 --denoise --stereo separate --trajectory .scenes/sponza_walk8.traj --out /tmp/ncu --radius 0.15 ;;
  quality)
    step quality 400 stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite quality --backend cuda --quality-variants "denoise;denoise, gather reuse;denoise, direct 2 passes, gather reuse;denoise, 4 passes, direct 2, gather reuse" --json $results/quality.json ;;
  scenes)
    step scenes $((590 - SECONDS)) stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite scenes --backend cuda --frames 300 --warmup 30 --scene-radius 0.15 --json $results/scenes.json ;;
  quality_still)
    step quality_still $((560 - SECONDS)) stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite quality --backend cuda --quality-scenes scenes/dabrovic-sponza.json --quality-variants "denoise, gather reuse" --json $results/quality_still.json ;;
  esac
done
