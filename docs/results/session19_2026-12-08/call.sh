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
  esac
done
