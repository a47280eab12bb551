#!/usr/bin/env bash
# Every render mode through the real executable on a small eye: exit 0 and the images written.
# Catches what unit tests cannot: the CLI's own handling of each mode's results. The third
# argument picks the backend (default cpu; the GPU machine runs it with cuda).
set -u
exe=$1
data=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
small=(--eye-size 64x72 --photons 32x32 --backend "${3:-cpu}")
failures=0
if [ "${3:-cpu}" = cuda ] && ! "$exe" render --backend cuda --eye-size 8x8 --photons 8x8 --out "$out/probe" >/dev/null 2>&1; then
  echo "no usable CUDA GPU: skipped"
  exit 77
fi
expect_render() {  # name, files expected under $out, arguments...
  local name=$1 files=$2
  shift 2
  "$exe" render cornell "${small[@]}" --out "$out/$name" "$@" >"$out/stdout" 2>"$out/stderr"
  local rc=$?
  if [ "$rc" -ne 0 ]; then
    echo "FAIL ($name: $*): exit code $rc: $(tail -3 "$out/stderr")"
    failures=$((failures + 1))
    return
  fi
  for f in $files; do
    if [ ! -s "$out/$f" ]; then
      echo "FAIL ($name: $*): $f not written"
      failures=$((failures + 1))
      return
    fi
  done
  echo "ok   ($name: $*)"
}
expect_render full "full_left.png full_right.exr"
expect_render gather "gather_right.png gather_right_reused.png" --stereo gather
expect_render scatter "scatter_right_reused.png" --stereo scatter
expect_render fov "fov_left.png fov_right.png" --foveated --gaze 0.3,0.6
expect_render fovgather "fovgather_right.png" --foveated --stereo gather
expect_render fovscatter "fovscatter_right.png" --foveated --stereo scatter --gaze 0.6,0.4
expect_render taa "taa_0004_left.png taa_0004_right.exr" --taa --trajectory "$data/gaze_pursuit.traj"
expect_render quarter "quarter_0004_left.png quarter_0004_right.png" --denoise --denoise-photon-passes quarter \
  --denoise-direct-iterations 2 --stereo gather --trajectory "$data/gaze_pursuit.traj"
expect_render raster "raster_left.png raster_right.exr" --primary raster --stereo gather
grep -q "raster pass" "$out/stdout" || { echo "FAIL: no raster pre-pass time printed"; failures=$((failures + 1)); }
expect_render rasterfov "rasterfov_0000_left.png rasterfov_0004_right.png" --primary raster --foveated --taa --trajectory "$data/gaze_pursuit.traj"
expect_render fovtaa "fovtaa_0000_left.png fovtaa_0004_right.png" --foveated --taa --taa-blend 0.2 --stereo gather \
  --trajectory "$data/gaze_pursuit.traj"
grep -q "TAA history kept on" "$out/stdout" || { echo "FAIL: no TAA history share printed"; failures=$((failures + 1)); }
# The budget controller over a trajectory: every frame's decision in PREFIX_control.json, and
# per-group levels given by name.
expect_render budget "budget_0004_left.png budget_control.json" --budget-ms 50 --trajectory "$data/gaze_pursuit.traj"
if ! grep -q '"frames_over_budget"' "$out/budget_control.json" || ! grep -q '"predicted_error"' "$out/budget_control.json" ||
   ! grep -q "controller: budget 50.00 ms" "$out/stdout"; then
  echo "FAIL (budget): no per-frame decisions in budget_control.json or no summary"
  failures=$((failures + 1))
fi
if "$exe" render cornell-caustics "${small[@]}" --effects specular=reflections,rest=shadows --out "$out/groups" \
     >"$out/stdout" 2>"$out/stderr" && [ -s "$out/groups_left.png" ]; then
  echo "ok   (effect groups by name)"
else
  echo "FAIL (effect groups by name): $(tail -3 "$out/stderr")"
  failures=$((failures + 1))
fi
# A viewer's settings file (foveation and TAA on) gives the reference its view; the reference
# renders every pixel regardless.
echo '{"foveated": true, "taa": true, "photons": "16x16", "head": {"position": [0.25, 0.1, 1.2], "orientation": [0, 0, 0, 1]}}' \
  >"$out/view_settings.json"
if "$exe" reference cornell --backend cpu --eye-size 24x24 --passes 2 --settings "$out/view_settings.json" --out "$out/refset" \
     >"$out/stdout" 2>"$out/stderr" && grep -q '0.25' "$out/refset.json" && grep -q "256 photons" "$out/stdout"; then
  echo "ok   (reference with a viewer's settings)"
else
  echo "FAIL (reference with a viewer's settings): $(tail -3 "$out/stderr")"
  failures=$((failures + 1))
fi
# The reference of a view, and a render compared against it.
if "$exe" reference cornell --backend cpu --eye-size 64x72 --photons 32x32 --spp 1 --passes 6 --out "$out/ref" \
     --compare "$out/full" >"$out/stdout" 2>"$out/stderr" && [ -s "$out/ref_left.exr" ] && [ -s "$out/ref.json" ] &&
   grep -q '"passes": 6' "$out/ref.json" && grep -q "against it: relMSE" "$out/stdout"; then
  echo "ok   (reference)"
else
  echo "FAIL (reference): $(tail -3 "$out/stderr")"
  failures=$((failures + 1))
fi
[ "$failures" -eq 0 ] && echo "all render modes passed" || echo "$failures render mode(s) failed"
exit $((failures > 0))
