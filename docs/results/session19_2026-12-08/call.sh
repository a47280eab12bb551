#!/usr/bin/env bash
# Nineteenth session (2026-12-08). Run from the repository root with carry [".gpu", ".gl", ".scenes"]
# (.scenes as in ../session15_2026-12-07/README.md, plus sponza_walk8.traj: the header and every 8th
# frame of sponza.traj, its first 24): call.sh PHASE... Phases owed from earlier sessions run from
# their scripts.
set -u
limit=${LIMIT:-580}
left() { echo $((limit - SECONDS)); }  # each script's LIMIT: what is left of this call's
for phase in "$@"; do
  case $phase in
  quarter)
    LIMIT=$(left) bash docs/results/session18_2026-12-07/call.sh quarter ;;
  walkfit_sponza_again | walkfit_sibenik | rays | photon_tests)
    LIMIT=$(left) bash docs/results/session17_2026-12-07/call.sh "$phase" ;;
  scenes)  # README's cathedral times and issue 13's targets: the scenes suite
    bash docs/results/nan_root_2026-12-07/call.sh scenes ;;
  quality_sponza)  # owed by `quarter` (cut there): Sponza's quality rows, with the longer history's
    ( source scripts/device-env.sh
      step quality_sponza $(($(left) - 20)) stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite quality --backend cuda \
        --quality-scenes scenes/dabrovic-sponza.json --no-quality-still \
        --quality-variants "denoise;denoise, history alpha 0.1;denoise, 4 passes, direct 2, gather reuse" \
        --json $results/quality_sponza.json ) ;;
  esac
done
