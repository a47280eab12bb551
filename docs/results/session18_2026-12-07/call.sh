#!/usr/bin/env bash
# Eighteenth session (2026-12-07; no device was lent, so nothing here has run yet). Run from the
# repository root with carry [".gpu", ".gl", ".scenes"] (.scenes as in ../session15_2026-12-07/README.md):
# call.sh PHASE... Phases owed from the seventeenth session (walkfit_sponza_again, walkfit_sibenik,
# rays, photon_tests) run from its script.
set -u
source scripts/device-env.sh
for phase in "$@"; do
  case $phase in
  walkfit_sponza_again | walkfit_sibenik | rays | photon_tests)
    bash docs/results/session17_2026-12-07/call.sh "$phase" ;;
  quarter)  # --denoise-photon-passes quarter: the GPU against the CPU, the sanitizers, ncu, then the quality rows
    step denoise_tests 120 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter='*Denois*'
    small=(--backend cuda --eye-size 320x352 --photons 128x128 --out /tmp/pvr_sanitized --trajectory tests/data/gaze_pursuit.traj
      --denoise --denoise-photon-passes quarter --denoise-direct-iterations 2)
    for tool in memcheck initcheck; do
      step ${tool}_quarter 60 compute-sanitizer --target-processes all --tool $tool --error-exitcode 9 \
        .gpu/run.sh .gpu/bin/photonvr render cornell "${small[@]}" --stereo gather
    done
    # The denoise kernels per eye on the Sponza walk, 4 passes with the direct signal through 2 (the
    # controller's cheapest step), full and quarter, separate eyes and gather reuse.
    metrics=gpu__time_duration.sum,launch__registers_per_thread,dram__bytes.sum,sm__throughput.avg.pct_of_peak_sustained_elapsed
    for passes in full quarter; do
      for stereo in separate gather; do
        step ncu_${passes}_$stereo 60 ncu --clock-control none --target-processes all \
          -k regex:"accumulate|variance|atrous|Atrous|remodulate" --launch-skip 60 -c 30 --csv --page raw --metrics $metrics \
          .gpu/run.sh .gpu/bin/photonvr render scenes/dabrovic-sponza.json --backend cuda --photons 512x512 --radius 0.15 \
          --denoise --denoise-iterations 4 --denoise-direct-iterations 2 --denoise-photon-passes $passes --stereo $stereo \
          --trajectory .scenes/sponza_walk8.traj --out /tmp/ncu_$passes
      done
    done
    # Time and error: the rows without the option beside the rows with it, both scenes.
    step quality $((${LIMIT:-580} - SECONDS)) stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite quality --backend cuda \
      --quality-scenes cornell,scenes/dabrovic-sponza.json --quality-variants "denoise, direct 2 passes;denoise, direct 2 passes, quarter photon passes;denoise, 4 passes, direct 2, gather reuse;denoise, 4 passes, direct 2, quarter photon passes, gather reuse" \
      --json $results/quality.json ;;
  esac
done
