#!/usr/bin/env bash
# Fourteenth session: where the reusing right eye's +Inf pixels come from (the still-head GPU
# test's report now redoes the first bad pixel's estimate from its stored gather point), whether
# compute-sanitizer's initcheck and racecheck see a read of unwritten memory or a shared-memory race
# in the same still frames, the scenes suite, and the controller suite's walk fit. Run from the
# repository root with carry [".gpu", ".gl", ".scenes"] (.scenes: the two scene folders and the
# trajectories named below): call.sh PHASE...
set -u
source scripts/device-env.sh
# The still head of the GPU test, under gather with the Auto schedule.
render_still=(.gpu/run.sh .gpu/bin/photonvr render scenes/dabrovic-sponza.json --backend cuda --photons 512x512
              --radius 0.15 --denoise --stereo gather --trajectory .scenes/still30.traj --out /tmp/still)
for phase in "$@"; do
  case $phase in
  nantest)
    step nan_test 110 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter=*ARefiningStillHead* --gtest_repeat=2 ;;
  nandiag)
    # A variant test binary (not committed) whose listed kernel, on a non-finite gather point,
    # shades the pixel again (shared-memory stack, then local stack) and prints both with the
    # thread's place (list index, block, SM, warp).
    step nan_diag 150 .gpu/run.sh .gpu/bin/pvr_gpu_tests_diag --gtest_filter=*ARefiningStillHead* --gtest_repeat=3 ;;
  sass)
    # The listed kernel's machine code and the device functions it calls, for a liveness check of
    # its registers (a read before any write would take a previous warp's leftovers).
    dump=$(command -v cuobjdump || ls /usr/local/cuda*/bin/cuobjdump | head -1)
    step sass_dump 120 bash -c "$dump -sass .gpu/bin/pvr_gpu_tests | awk '/Function : /{keep = \$0 ~ /listedEyeRaysKernel|eyeRaysKernelILNS_10StereoRoleE0ELb0E|DirectLight|pathTracedRadiance|clipAtBoundaries|bsdfAt|occlusionAt|sampleBsdf|texelPasses/} keep' | xz -6 > $results/listed_sass.txt.xz; ls -la $results/listed_sass.txt.xz" ;;
  initcheck)
    step initcheck 150 compute-sanitizer --tool initcheck --print-limit 30 "${render_still[@]}" ;;
  racecheck)
    step racecheck 120 compute-sanitizer --tool racecheck --racecheck-report hazard --print-limit 30 "${render_still[@]}" ;;
  tests)
    step gpu_tests 90 .gpu/run.sh .gpu/bin/pvr_gpu_tests ;;
  scenes)
    step scenes 170 stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite scenes --backend cuda --frames 300 --warmup 30 --scene-radius 0.15 --json $results/scenes.json ;;
  controller_sponza)
    step controller_sponza $((580 - SECONDS)) stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite controller --backend cuda \
      --walks scenes/dabrovic-sponza.json=.scenes/sponza.traj --budgets 11.1,5.5 \
      --profiles docs/results/h200-2026-12-03/profile --profile-out $results/walkfit --error-every 270 --fixed-stride 9 \
      --reference-passes 4 --json $results/controller_sponza.json ;;
  controller_sibenik)
    step controller_sibenik $((580 - SECONDS)) stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite controller --backend cuda \
      --walks scenes/sibenik.json=.scenes/sibenik.traj --budgets 11.1,5.5 \
      --profiles docs/results/h200-2026-12-03/profile --profile-out $results/walkfit --error-every 270 --fixed-stride 9 \
      --reference-passes 4 --json $results/controller_sibenik.json ;;
  esac
done
