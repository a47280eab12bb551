#!/usr/bin/env bash
# photonvr xr against a real OpenXR runtime (found through XR_RUNTIME_JSON; skipped, exit 77,
# when none is set). The session runs its whole life cycle: --frames N ends it through
# xrRequestExitSession, Ctrl-C does the same, and both exit 0 in state EXITING.
# Runs with Monado (simulated HMD) headless: XRT_COMPOSITOR_NULL=1 SIMULATED_ENABLE=1.
set -u
exe=$1
backend=${2:-cpu}
[ -n "${XR_RUNTIME_JSON:-}" ] || { echo "SKIP: XR_RUNTIME_JSON is not set (no OpenXR runtime)"; exit 77; }
[ -f "$XR_RUNTIME_JSON" ] || { echo "FAIL: XR_RUNTIME_JSON=$XR_RUNTIME_JSON does not exist"; exit 1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
flat() { tr -d ' \n' <"$1"; }

timeout 120 "$exe" xr --backend "$backend" --photons 64x64 --frames 40 --stats "$out/a.json" >"$out/a.log" 2>&1
rc=$?
grep -v WARN "$out/a.log"
[ $rc -eq 0 ] || fail "xr --frames 40: exit code $rc"
flat "$out/a.json" | grep -q '"final_state":"EXITING"' || fail "session did not end in EXITING"
flat "$out/a.json" | grep -q '"frames":40,' || fail "not 40 frames rendered"

timeout 120 "$exe" xr --backend "$backend" --photons 64x64 --no-depth --eye-size 96x80 --stats "$out/b.json" >"$out/b.log" 2>&1 &
pid=$!
sleep 4
kill -INT $pid
wait $pid
rc=$?
[ $rc -eq 0 ] || fail "xr after Ctrl-C: exit code $rc"
flat "$out/b.json" | grep -q '"stopped_by_signal":true' || fail "Ctrl-C not recorded"
flat "$out/b.json" | grep -q '"final_state":"EXITING"' || fail "Ctrl-C: session did not end in EXITING"
flat "$out/b.json" | grep -q '"depth_layer":false' || fail "--no-depth still submitted depth"
flat "$out/b.json" | grep -q '"eye_size":\[96,80\]' || fail "--eye-size not used"
echo "xr runtime ok"
