#!/usr/bin/env bash
# Sixteenth session (2026-12-07): the foveated pass's workaround (a30ef05, finishShadingTogether)
# on a GPU, then the measurements it held up. Run from the repository root with carry
# [".gpu", ".gl", ".scenes"] (.scenes as in ../session15_2026-12-07/README.md): call.sh PHASE...
set -u
here=docs/results
for phase in "$@"; do
  case $phase in
  check)
    # What the first call ran (listed: the reproduction, since folded into the still-head test).
    REPEAT=2 bash $here/session15_2026-12-07/call.sh fovea_check tests vertex_sass listed ;;
  auto)
    # Owed: Auto's listed pass as the default, the still-head test's seven runs twice, and the
    # scenes suite (README's cathedral times).
    REPEAT=2 bash $here/session15_2026-12-07/call.sh nantest
    bash $here/nan_root_2026-12-07/call.sh scenes ;;
  rays)
    # The ray kernels' rates beside the photon pass's at 256^2..2048^2 photons (bench --suite rays).
    bash -c 'source scripts/device-env.sh; step rays 150 stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite rays \
      --rays-scenes cornell-dense,scenes/dabrovic-sponza.json,scenes/sibenik.json --json $results/rays.json' ;;
  walkfit_sponza) bash $here/nan_root_2026-12-07/call.sh controller_sponza ;;
  walkfit_sibenik) bash $here/nan_root_2026-12-07/call.sh controller_sibenik ;;
  esac
done
