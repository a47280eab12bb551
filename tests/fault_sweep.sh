# Sourced by tests/faults.sh and tests/gpu_faults.sh: the sweep of an injected fault over a run,
# and the inputs both tests make.
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

# The fault tests' inputs. A textured quad in the Cornell box: DIR/NAME.json, a mesh whose map_Kd
# is TEXTURE (a file name in DIR).
write_textured_quad() {  # DIR NAME TEXTURE
  printf 'newmtl m\nKd 0.8 0.8 0.8\nmap_Kd %s\n' "$3" >"$1/$2.mtl"
  printf 'mtllib %s.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl m\nf 1/1 4/4 3/3 2/2\n' \
    "$2" >"$1/$2.obj"
  printf '{"base": "cornell", "meshes": [{"file": "%s.obj", "scale": 0.2, "translate": [0, 0.2, 0]}]}\n' "$2" >"$1/$2.json"
}
# Three frames of a small step and turn with a moving gaze: FILE.
write_three_frames() {  # FILE
  printf '0 0.5 2.6 0 0 0 1 0.4 0.5\n0.02 0.5 2.6 0 0.02 0 1 0.5 0.5\n0.04 0.5 2.6 0 0.04 0 1 0.6 0.5\n' >"$1"
}
