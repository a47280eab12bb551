#!/usr/bin/env bash
# Seventeenth session (2026-12-07). Run from the repository root with carry [".gpu", ".gl", ".scenes"]
# (.scenes as in ../session15_2026-12-07/README.md): call.sh PHASE... Each output line of the long
# controller phases starts with the seconds since the phase began (where the time goes).
set -u
source scripts/device-env.sh
here=docs/results/session17_2026-12-07
stamped() { local began=$SECONDS; "$@" 2>&1 | while IFS= read -r line; do echo "$((SECONDS - began)) s | $line"; done; return "${PIPESTATUS[0]}"; }
controller() {  # SCENE TRAJECTORY NAME [more bench options]
  local scene=$1 traj=$2 name=$3
  shift 3
  step "$name" $((${LIMIT:-580} - SECONDS)) stdbuf -oL bash -c "$(declare -f stamped); stamped .gpu/run.sh .gpu/bin/photonvr bench \
    --suite controller --backend cuda --walks $scene=$traj --budgets 11.1,5.5 --error-every 270 \
    --reference-passes 4 --json $results/$name.json $*"
}
for phase in "$@"; do
  case $phase in
  auto)  # the first call: the still-head test twice under Auto's listed pass, and the scenes suite
    bash docs/results/session16_2026-12-07/call.sh auto ;;
  walkfit_sponza)  # the second call (cut at 579 s, after the fit and the controller's walks)
    bash docs/results/session16_2026-12-07/call.sh walkfit_sponza ;;
  controller_sponza)  # the controller and the fixed settings with the second call's fitted profile
    controller scenes/dabrovic-sponza.json .scenes/sponza.traj controller_sponza \
      --profiles $here/walkfit --fixed-stride 9 ;;
  walkfit_sponza_again)  # the fit and the walks anew on Sponza, with the views and histories of e969a30
    controller scenes/dabrovic-sponza.json .scenes/sponza.traj walkfit_sponza_again \
      --profiles docs/results/h200-2026-12-03/profile --profile-out $results/walkfit --fixed-stride 9 ;;
  walkfit_sibenik)  # the fit and the walks (the per-frame error is relMSE alone since the third call: the SSIM took most of the second call)
    controller scenes/sibenik.json .scenes/sibenik.traj walkfit_sibenik \
      --profiles docs/results/h200-2026-12-03/profile --profile-out $results/walkfit --fixed-stride 9 ;;
  rays)  # the ray kernels, and the photon pass over the binary and the 8-wide BVH at 256^2..2048^2 photons
    step rays 200 stdbuf -oL .gpu/run.sh .gpu/bin/photonvr bench --suite rays \
      --rays-scenes cornell-dense,scenes/dabrovic-sponza.json,scenes/sibenik.json --json $results/rays.json ;;
  photon_tests)  # the stored photons against the CPU's over both BVHs
    step photon_tests 60 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter=*StoredPhotonsMatchTheCpu* ;;
  esac
done
