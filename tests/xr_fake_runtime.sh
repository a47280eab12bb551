#!/usr/bin/env bash
# photonvr xr against the test runtime (tests/fake_xr_runtime) on this machine's Vulkan device
# (lavapipe in CI): a whole session whose frames are handed into the runtime's swapchain images,
# and every OpenXR failure photonvr reports, each provoked by PVR_FAKE_XR: one line on stderr,
# a non-zero exit, no hang.
set -u
exe=$1
export XR_RUNTIME_JSON=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
failures=0
small=(--backend cpu --photons 16x16)

PVR_FAKE_XR=ok timeout 120 "$exe" xr "${small[@]}" --frames 12 --stats "$out/ok.json" >"$out/ok.log" 2>"$out/ok.err"
rc=$?
flat=$(tr -d ' \n' <"$out/ok.json" 2>/dev/null)
if [ $rc -ne 0 ] || [ -s "$out/ok.err" ] || ! grep -q '"final_state":"EXITING"' <<<"$flat" || ! grep -q '"frames":12,' <<<"$flat" ||
   ! grep -q '"depth_layer":true' <<<"$flat" || ! grep -q '"eye_size":\[64,48\]' <<<"$flat"; then
  echo "FAIL (a session): exit $rc, stderr: $(cat "$out/ok.err")"
  cat "$out/ok.log"
  failures=$((failures + 1))
else
  echo "ok   (a session of 12 frames at the runtime's 64x48, depth layer, ended in EXITING)"
fi

# Keys during a session (piped with --stdin-keys, one a frame): 2, e, then 0, each reported once in
# that order; the run ends at the scene's own levels.
printf '2\ne0' | PVR_FAKE_XR=ok timeout 120 "$exe" xr "${small[@]}" --frames 8 --stdin-keys --stats "$out/keys.json" \
  >"$out/keys.log" 2>"$out/keys.err"
rc=$?
keys=$(grep -o "key '.*" "$out/keys.log" | tr '\n' '|')
if [ $rc -ne 0 ] || [ -s "$out/keys.err" ] ||
   [ "$keys" != "key '2': every material at shadows|key 'e': every material at reflections|key '0': each material at its own level|" ] ||
   ! tr -d ' \n' <"$out/keys.json" | grep -q '"effects":"permaterial"'; then
  echo "FAIL (keys): exit $rc, keys '$keys', stderr: $(cat "$out/keys.err")"
  failures=$((failures + 1))
else
  echo "ok   (keys 2, e, 0 applied on successive frames: shadows, reflections, the scene's own levels)"
fi

# Controller buttons through OpenXR actions (the test runtime has a simple controller in each
# hand): right select held on frames 3-4 (one press), pressed again on 6, left select on 8: every
# material at raster, then shadows, then the scene's own levels; all five core profiles bound.
right=/user/hand/right/input/select/click left=/user/hand/left/input/select/click
PVR_FAKE_XR=ok PVR_FAKE_XR_PRESS="3:$right,4:$right,6:$right,8:$left" timeout 120 "$exe" xr "${small[@]}" --frames 12 \
  --stats "$out/buttons.json" >"$out/buttons.log" 2>"$out/buttons.err"
rc=$?
presses=$(grep -o "controller (.*" "$out/buttons.log" | tr '\n' '|')
flat=$(tr -d ' \n' <"$out/buttons.json" 2>/dev/null)
if [ $rc -ne 0 ] || [ -s "$out/buttons.err" ] ||
   [ "$presses" != "controller (next level): every material at raster|controller (next level): every material at shadows|controller (the scene's levels): each material at its own level|" ] ||
   ! grep -q '"controller_presses":3,' <<<"$flat" || ! grep -q '"controller_profiles":5,' <<<"$flat" ||
   ! grep -q '"effects":"permaterial"' <<<"$flat"; then
  echo "FAIL (controller): exit $rc, presses '$presses', stderr: $(cat "$out/buttons.err")"
  failures=$((failures + 1))
else
  echo "ok   (controller buttons: held over two frames counts once; raster, shadows, the scene's own levels)"
fi

# Focus lost (frames 4-8: a system menu) while a button is pressed and held (frames 5-9): that is no
# press, whether the runtime answers the sync with XR_SESSION_NOT_FOCUSED or the presenter skips it
# unfocused, or the button is already down when focus comes back. Presses before and after count.
held=""
for f in 5 6 7 8 9; do held="$held,$f:$right"; done
PVR_FAKE_XR=unfocus PVR_FAKE_XR_PRESS="2:$right$held,12:$right" timeout 120 "$exe" xr "${small[@]}" --frames 14 \
  --stats "$out/unfocus.json" >"$out/unfocus.log" 2>"$out/unfocus.err"
rc=$?
presses=$(grep -o "controller (.*" "$out/unfocus.log" | tr '\n' '|')
if [ $rc -ne 0 ] || [ -s "$out/unfocus.err" ] ||
   [ "$presses" != "controller (next level): every material at raster|controller (next level): every material at shadows|" ] ||
   ! tr -d ' \n' <"$out/unfocus.json" | grep -q '"controller_presses":2,'; then
  echo "FAIL (unfocus): exit $rc, presses '$presses', stderr: $(cat "$out/unfocus.err")"
  failures=$((failures + 1))
else
  echo "ok   (unfocus: a button held while focus was away is no press)"
fi

# A runtime that takes no controller binding: one warning line, and the session runs on.
PVR_FAKE_XR=nocontrollers timeout 120 "$exe" xr "${small[@]}" --frames 4 --stats "$out/none.json" >"$out/none.log" 2>"$out/none.err"
rc=$?
if [ $rc -ne 0 ] || [ "$(wc -l <"$out/none.err")" -ne 1 ] || ! grep -q "took no controller bindings" "$out/none.err" ||
   ! tr -d ' \n' <"$out/none.json" | grep -q '"controller_profiles":0,'; then
  echo "FAIL (nocontrollers): exit $rc, stderr: $(cat "$out/none.err")"
  failures=$((failures + 1))
else
  echo "ok   (nocontrollers): $(cat "$out/none.err")"
fi

expect_error() {  # mode, expected-substring, extra arguments...
  local mode=$1 expected=$2
  shift 2
  PVR_FAKE_XR=$mode timeout 60 "$exe" xr "${small[@]}" --frames 20 --stats "" "$@" >"$out/stdout" 2>"$out/stderr"
  local rc=$?
  local lines
  lines=$(wc -l <"$out/stderr")
  if [ "$rc" -eq 0 ] || [ "$rc" -ge 124 ]; then
    echo "FAIL ($mode): exit code $rc"
    failures=$((failures + 1))
  elif [ "$lines" -ne 1 ] || ! grep -qi -- "$expected" "$out/stderr"; then
    echo "FAIL ($mode): expected one line with '$expected', got: $(cat "$out/stderr")"
    failures=$((failures + 1))
  else
    echo "ok   ($mode): $(cat "$out/stderr")"
  fi
}

expect_error noext "does not offer XR_KHR_vulkan_enable2"
expect_error nohmd "no headset connected"
expect_error binding "refused the Vulkan graphics binding"
expect_error formats "offers no colour swapchain format"
expect_error noready "did not become ready within 1 s" --ready-timeout 1
expect_error lost "session was lost"
expect_error norelease "did not release a swapchain image"

[ "$failures" -eq 0 ] && echo "all OpenXR cases passed" || echo "$failures OpenXR case(s) failed"
exit $((failures > 0))
