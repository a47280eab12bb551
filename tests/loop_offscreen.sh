#!/usr/bin/env bash
# The frame loop offscreen on the CPU backend (the benchmark mode CI can run): the frames it was
# asked for, every one handed to Vulkan images (lavapipe here), none late for a 1 Hz display,
# and the statistics written as JSON with p50/p99/max. Under the sanitizers, whose frames take 10-20
# times as long (about 1.1 s under TSan on 2 busy cores), the display's rate is
# PVR_LOOP_TEST_REFRESH_HZ (scripts/test-sanitizers.sh and test-tsan.sh set 0.25).
set -u
exe=$1
refresh=${PVR_LOOP_TEST_REFRESH_HZ:-1}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$exe" xr --offscreen --backend cpu --eye-size 48x40 --photons 32x32 --frames 12 --warmup 2 --refresh "$refresh" \
  --stats "$out/stats.json" >"$out/log" 2>&1
rc=$?
cat "$out/log"
fail() { echo "FAIL: $*"; exit 1; }
[ $rc -eq 0 ] || fail "exit code $rc"
tr -d ' \n' <"$out/stats.json" >"$out/flat"
grep -q '"frames":12,' "$out/flat" || fail "not 12 frames in the statistics"
grep -q '"missed_deadlines":0,' "$out/flat" || fail "deadlines missed at $refresh Hz"
grep -q '"handover":"hoststagingbuffer"' "$out/flat" || fail "no Vulkan hand-over"
grep -q '"cpu_ms":{"max":[0-9.e-]*,"mean":[0-9.e-]*,"p50":[0-9.e-]*,"p99":[0-9.e-]*}' "$out/flat" || fail "no cpu_ms percentiles"
grep -q '"handover_ms":{' "$out/flat" || fail "no hand-over timing"
# A key piped in (--stdin-keys): every material at the path level from the first frame on.
printf '5' | "$exe" xr --offscreen --backend cpu --eye-size 48x40 --photons 32x32 --frames 3 --refresh 1 --handover none \
  --stdin-keys --stats "$out/keys.json" >"$out/log" 2>&1 || { rc=$?; cat "$out/log"; fail "exit code $rc with --stdin-keys"; }
grep -q "xr: frame 0: key '5': every material at path" "$out/log" || { cat "$out/log"; fail "key 5 not applied at frame 0"; }
tr -d ' \n' <"$out/keys.json" | grep -q '"effects":"path"' || fail "the statistics do not show the path level"
# Under the budget controller: its decisions in the statistics, a summary line, no frame lost
# (the stats outlive the controller: this once read freed memory).
"$exe" xr --offscreen --backend cpu --eye-size 48x40 --frames 12 --warmup 2 --refresh 1 --handover none \
  --budget-ms 500 --stats "$out/budget.json" >"$out/log" 2>&1 || { cat "$out/log"; fail "exit code $? under --budget-ms"; }
tr -d ' \n' <"$out/budget.json" >"$out/flat"
grep -q '"controller":{"budget_ms":500' "$out/flat" || fail "no controller in the statistics"
grep -q '"change":"start"' "$out/flat" || fail "no per-frame decisions"
grep -q "controller: budget 500.00 ms" "$out/log" || fail "no controller summary"
# --budget-ms display: the budget is the display's period, here the offscreen slot of 2 Hz.
"$exe" xr --offscreen --backend cpu --eye-size 48x40 --frames 6 --warmup 1 --refresh 2 --handover none \
  --budget-ms display --stats "$out/display.json" >"$out/log" 2>&1 || { cat "$out/log"; fail "exit code $? under --budget-ms display"; }
tr -d ' \n' <"$out/display.json" | grep -q '"controller":{"budget_ms":500' || { cat "$out/display.json"; fail "the budget is not the display's period"; }
grep -q "controller: budget 500.00 ms" "$out/log" || fail "no controller summary under --budget-ms display"
echo "offscreen loop ok"
