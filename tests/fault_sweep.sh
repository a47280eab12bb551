# Sourced by tests/faults.sh and tests/gpu_faults.sh: the sweep of an injected fault over a run.
#   fault_sweep NAME KIND EXPECTED COMMAND...
# runs COMMAND with PVR_INJECT_FAULT=KIND:1, KIND:2, ... Each run must end with one line on stderr
# containing EXPECTED, exit code 1, within 60 s (no hang). The sweep ends at the first N the run
# outlives, which must then say that its planned event did not happen after N - 1 events (else
# the fault was swallowed). Prints one block as it ends: "ok ..." with the allocation sites that
# failed (the CUDA ones name theirs), or "FAIL: ...". Needs `fault_sweep_dir`, a folder of its own.
fault_sweep() {
  local name=$1 kind=$2 expected=$3
  shift 3
  local dir n rc start
  dir=$(mktemp -d -p "$fault_sweep_dir")
  : >"$dir/sites"
  : >"$dir/secs"
  for ((n = 1; n <= 400; ++n)); do
    start=$SECONDS
    PVR_INJECT_FAULT=$kind:$n timeout 60 "$@" >"$dir/stdout" 2>"$dir/stderr"
    rc=$?
    if [ $rc -eq 0 ]; then
      if ! grep -q "fault plan $kind:$n: $((n - 1)) $kind events, the planned one did not happen" "$dir/stderr"; then
        echo "FAIL: $name: $kind:$n: the run went on: $(cat "$dir/stderr")"
      elif [ $n -eq 1 ]; then
        echo "FAIL: $name: no $kind event happened"
      else
        local report
        report="ok   $name: $((n - 1)) $kind event(s), each one line and exit 1 (slowest $(sort -n "$dir/secs" | tail -1) s); e.g. $(cat "$dir/first")"
        [ -s "$dir/sites" ] && report+=$'\n'$(sort "$dir/sites" | uniq -c | sed 's/^ */       /')
        printf '%s\n' "$report"
      fi
      return
    fi
    echo $((SECONDS - start)) >>"$dir/secs"
    if [ $rc -ge 124 ]; then
      echo "FAIL: $name: $kind:$n: exit code $rc (a hang or a crash): $(cat "$dir/stderr")"
      return
    fi
    if [ $rc -ne 1 ] || [ "$(grep -c . "$dir/stderr")" -ne 1 ] || ! grep -q -- "$expected" "$dir/stderr"; then
      echo "FAIL: $name: $kind:$n: exit code $rc, expected one line with '$expected', got: $(cat "$dir/stderr")"
      return
    fi
    [ $n -eq 1 ] && cp "$dir/stderr" "$dir/first"
    sed -n 's/.*GPU out of memory: \(.*\) needs .*/\1/p' "$dir/stderr" >>"$dir/sites"
  done
  echo "FAIL: $name: more than 400 $kind events"
}
