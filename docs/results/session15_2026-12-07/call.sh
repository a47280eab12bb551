#!/usr/bin/env bash
# Fifteenth session (2026-12-07): the controller suite's walk fit stopped with "an illegal memory
# access" in its first foveated walk (1024^2 photons, 1.4 r, 4 denoiser passes, after ten
# non-foveated walks on the same renderer). Run from the repository root with carry
# [".gpu", ".gl", ".scenes"] (.scenes: dabrovic-sponza/, sponza_every9.traj = every 9th line of
# sponza.traj, sponza_every9_30.traj = its first 30; sponza.traj and still30.traj for the
# controller and the still head): call.sh PHASE...
set -u
source scripts/device-env.sh
fovea=(render scenes/dabrovic-sponza.json --backend cuda --photons 1024x1024 --radius 0.21 --denoise
       --denoise-iterations 4 --denoise-direct-iterations 4 --foveated --out /tmp/fovea)
for phase in "$@"; do
  case $phase in
  fovea_blocking)
    # The fit's foveated walk alone, each kernel waited for: a fault names its kernel.
    step fovea_blocking 90 env CUDA_LAUNCH_BLOCKING=1 .gpu/run.sh .gpu/bin/photonvr "${fovea[@]}" \
      --trajectory .scenes/sponza_every9.traj ;;
  fovea_memcheck)
    step fovea_memcheck 200 compute-sanitizer --tool memcheck --print-limit 20 .gpu/run.sh .gpu/bin/photonvr "${fovea[@]}" \
      --trajectory .scenes/sponza_every9_30.traj ;;
  fovea_xr)
    # The same walk, all 300 frames, through the frame loop (no image written a frame).
    step fovea_xr 90 env CUDA_LAUNCH_BLOCKING=1 .gpu/run.sh .gpu/bin/photonvr xr --offscreen scenes/dabrovic-sponza.json \
      --backend cuda --photons 1024x1024 --radius 0.21 --denoise --denoise-iterations 4 --denoise-direct-iterations 4 \
      --foveated --trajectory .scenes/sponza_every9.traj --frames 300 --stats $results/fovea_xr.json ;;
  fovea_xr_memcheck)
    # Its first frames under memcheck: which access faults.
    step fovea_xr_memcheck 150 compute-sanitizer --tool memcheck --print-limit 12 .gpu/run.sh .gpu/bin/photonvr xr \
      --offscreen scenes/dabrovic-sponza.json --backend cuda --photons 1024x1024 --radius 0.21 --denoise \
      --denoise-iterations 4 --denoise-direct-iterations 4 --foveated --trajectory .scenes/sponza_every9.traj --frames 3 \
      --stats /tmp/fovea_xr_memcheck.json ;;
  fovea_bisect)
    # The first N frames of the walk that fail (blocking), then memcheck over the 25 before.
    xr=(.gpu/run.sh .gpu/bin/photonvr xr --offscreen scenes/dabrovic-sponza.json --backend cuda --photons 1024x1024
        --radius 0.21 --denoise --denoise-iterations 4 --denoise-direct-iterations 4 --foveated)
    grep -v '^#' .scenes/sponza_every9.traj > /tmp/walk.traj
    for n in 25 50 75 100 125 150 175 200 225 250 275 300; do
      step fovea_first_$n 40 env CUDA_LAUNCH_BLOCKING=1 "${xr[@]}" --trajectory /tmp/walk.traj --frames $n --stats /tmp/s.json
      if ! tail -1 $results/steps.txt | grep -q 'rc=0'; then
        sed -n "$((n - 24)),${n}p" /tmp/walk.traj > /tmp/last25.traj
        cp /tmp/last25.traj $results/last25.traj
        step fovea_last25_memcheck 100 compute-sanitizer --tool memcheck --print-limit 12 "${xr[@]}" \
          --trajectory /tmp/last25.traj --frames 25 --stats /tmp/s.json
        break
      fi
    done ;;
  fovea_exact)
    # The failing frame to within 5, then memcheck over every frame up to it (the fault depends on
    # the frame's place in the run: a fresh run over frames 176-200 under memcheck was clean).
    xr=(.gpu/run.sh .gpu/bin/photonvr xr --offscreen scenes/dabrovic-sponza.json --backend cuda --photons 1024x1024
        --radius 0.21 --denoise --denoise-iterations 4 --denoise-direct-iterations 4 --foveated)
    grep -v '^#' .scenes/sponza_every9.traj > /tmp/walk.traj
    last=200
    for n in 180 185 190 195; do
      step fovea_first_$n 40 env CUDA_LAUNCH_BLOCKING=1 "${xr[@]}" --trajectory /tmp/walk.traj --frames $n --stats /tmp/s.json
      if ! tail -1 $results/steps.txt | grep -q 'rc=0'; then last=$n; break; fi
    done
    step fovea_memcheck_first_$last 200 compute-sanitizer --tool memcheck --print-limit 12 "${xr[@]}" \
      --trajectory /tmp/walk.traj --frames $last --stats /tmp/s.json ;;
  vertex_sass)
    # The foveated eye pass's machine code with its source lines (nvdisasm -g), for the faulting
    # read memcheck placed at traceToGatherPoint+0xa8fe0 (gather.h:331, through params).
    bin=$(dirname "$(command -v cuobjdump || ls /usr/local/cuda*/bin/cuobjdump | head -1)")
    step vertex_sass 150 bash -c "mkdir -p /tmp/cubins && cd /tmp/cubins && $bin/cuobjdump -xelf all $PWD/.gpu/bin/photonvr >/dev/null &&
      f=\$(grep -l vertexRaysKernel *.cubin | head -1) && echo \$f && $bin/nvdisasm -g -c \$f | xz -6 > $results/foveated_sass.txt.xz &&
      $bin/cuobjdump -res-usage \$f | grep -A1 -i 'vertexRays\|traceToGather' | head -40; ls -la $results" ;;
  fovea_check)
    # The list kernels' workaround (finishShadingTogether): the walk that faulted by frame 185,
    # all 300 frames twice with each kernel waited for, and its first 185 under memcheck.
    xr=(.gpu/run.sh .gpu/bin/photonvr xr --offscreen scenes/dabrovic-sponza.json --backend cuda --photons 1024x1024
        --radius 0.21 --denoise --denoise-iterations 4 --denoise-direct-iterations 4 --foveated)
    grep -v '^#' .scenes/sponza_every9.traj > /tmp/walk.traj
    for k in 1 2; do
      step fovea_300_$k 40 env CUDA_LAUNCH_BLOCKING=1 "${xr[@]}" --trajectory /tmp/walk.traj --frames 300 --stats /tmp/s.json
    done
    step fovea_memcheck_185 120 compute-sanitizer --tool memcheck --print-limit 12 "${xr[@]}" \
      --trajectory /tmp/walk.traj --frames 185 --stats /tmp/s.json ;;
  nantest)
    # The still head under the new Auto (the reusing right eye's rays in its eye kernel).
    step nan_test 120 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter=*ARefiningStillHead* --gtest_repeat=${REPEAT:-2} ;;
  listed)
    # The open bug's reproduction: the listed right-eye pass (FirstHits under gather). The test is
    # gone since 94c1508 (folded into the still-head test's runs): use `nantest` after that.
    step listed 80 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter=*TheListedRightEyePass* \
      --gtest_also_run_disabled_tests --gtest_repeat=${REPEAT:-2} ;;
  tests)
    step gpu_tests 150 .gpu/run.sh .gpu/bin/pvr_gpu_tests ;;
  controller_blocking)
    # The walk fit that stopped, each kernel waited for: the fault names its kernel.
    step controller_blocking $((560 - SECONDS)) env CUDA_LAUNCH_BLOCKING=1 stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench \
      --suite controller --backend cuda --walks scenes/dabrovic-sponza.json=.scenes/sponza.traj --budgets 11.1,5.5 \
      --profiles docs/results/h200-2026-12-03/profile --profile-out $results/walkfit --error-every 270 --fixed-stride 9 \
      --reference-passes 4 --json $results/controller_sponza.json ;;
  esac
done
