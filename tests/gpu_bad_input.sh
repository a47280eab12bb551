#!/usr/bin/env bash
# GPU failures through the real executable: one line on stderr, exit 1, never a crash.
# Exits 77 (skipped) where no CUDA GPU is present, after checking that --backend cuda says so.
exe=$1
err=$(mktemp)
trap 'rm -f "$err"' EXIT
if ! "$exe" render --backend cuda --eye-size 8x8 --photons 8x8 --out /tmp/pvr_gpu_probe 2>"$err" >/dev/null; then
  lines=$(wc -l <"$err")
  if [ "$lines" -eq 1 ] && grep -q "^photonvr: error: --backend cuda: no" "$err"; then
    echo "no GPU: --backend cuda fails with one line, as it should: $(cat "$err")"
    exit 77
  fi
  echo "FAIL: --backend cuda failed without the one-line no-GPU error:"; cat "$err"; exit 1
fi
fail=0
expect_oom() {
  local rc
  PVR_GPU_MEMORY_LIMIT_MB=$1 "$exe" "${@:2}" >/dev/null 2>"$err"; rc=$?
  if [ $rc -ne 1 ] || [ "$(wc -l <"$err")" -ne 1 ] || ! grep -q "GPU out of memory" "$err"; then
    echo "FAIL (rc $rc): $*"; cat "$err"; fail=1
  else
    echo "ok: $(cat "$err")"
  fi
}
expect_oom 1 render --backend cuda --out /tmp/pvr_gpu_oom
expect_oom 40 render --backend cuda --photons 512x512 --out /tmp/pvr_gpu_oom
expect_oom 200 render --backend cuda --eye-size 8192x8192 --eyes left --out /tmp/pvr_gpu_oom
PVR_GPU_MEMORY_LIMIT_MB=abc "$exe" render --backend cuda --out /tmp/pvr_gpu_oom >/dev/null 2>"$err"
if [ $? -ne 1 ] || ! grep -q "PVR_GPU_MEMORY_LIMIT_MB" "$err"; then echo "FAIL: bad limit"; cat "$err"; fail=1; fi
exit $fail
