#!/usr/bin/env bash
# Thirteenth session: which right-eye path renders the still head's non-finite pixels under gather
# reuse (the GPU test's ray-schedule matrix), memcheck over the same still frames, the GPU suite
# (the denoiser's non-finite guard), the scenes suite on the card issue 13 names, and the quality
# bench's Sponza still head. Run from the repository root with carry [".gpu", ".gl", ".scenes"]:
# call.sh PHASE...
set -u
source scripts/device-env.sh
for phase in "$@"; do
  case $phase in
  nantest)
    step nan_test 90 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter=*ARefiningStillHead* ;;
  nosparse)
    # A variant build (not committed) whose reusing right eye estimates its gather points with the
    # hybrid scheme's tiled kernel instead of a warp per listed point (eye_pass.cu: sparse = false),
    # bundled beside the others: is that kernel the cause?
    step nan_test_nosparse 90 .gpu/run.sh .gpu/bin/pvr_gpu_tests_nosparse --gtest_filter=*ARefiningStillHead* ;;
  tests)
    step gpu_tests 90 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter=-*ARefiningStillHead* ;;
  scenes)
    step scenes 170 stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite scenes --backend cuda --frames 300 --warmup 30 --scene-radius 0.15 --json $results/scenes.json ;;
  memcheck)
    step memcheck 100 compute-sanitizer --tool memcheck --print-limit 20 .gpu/run.sh .gpu/bin/photonvr render scenes/dabrovic-sponza.json --backend cuda --photons 512x512 --radius 0.15 --denoise --stereo gather --trajectory .scenes/still120.traj --out /tmp/memcheck ;;
  quality_still)
    step quality_still $((560 - SECONDS)) stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite quality --backend cuda --quality-scenes scenes/dabrovic-sponza.json --quality-variants "denoise, gather reuse" --json $results/quality_still.json ;;
  esac
done
