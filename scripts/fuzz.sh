#!/usr/bin/env bash
# Fuzzes photonvr's input parsers with libFuzzer (clang, ASan + UBSan, leaks checked): the JSON
# scene format, mesh import (glTF/GLB/OBJ through assimp), foveation masks, trajectories and the
# command line (parsed and checked, nothing run).
#   usage: scripts/fuzz.sh [SECONDS_PER_HARNESS (default 30)] [BUILD_DIR (default build-fuzz)] [HARNESS,...]
#   PVR_FUZZ_SANITIZERS (default address,undefined) and PVR_FUZZ_FORK (libFuzzer workers, default
#   1) for long runs on many cores, e.g. PVR_FUZZ_FORK=16 scripts/fuzz.sh 3600 build-fuzz mesh,cli.
# Seeds: the project's test data and scenes, and Debian's assimp-testmodels (its glTF2 samples,
# broken glTF2 files and invalid/ models). Prints one line per harness (executions, findings);
# a finding's input lands in BUILD_DIR/artifacts/HARNESS/ and the script exits non-zero.
set -euo pipefail
cd "$(dirname "$0")/.."
# clang and its libFuzzer runtime (Debian 12: clang 14), on top of the build's dependencies.
bash scripts/install-deps.sh clang libclang-rt-14-dev
seconds=${1:-30}
build=${2:-build-fuzz}
sanitizers=${PVR_FUZZ_SANITIZERS:-address,undefined}
fork=${PVR_FUZZ_FORK:-1}
flags="-fsanitize=fuzzer-no-link,$sanitizers -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPVR_ENABLE_CUDA=OFF -DPVR_FUZZ=ON \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=$sanitizers" >/dev/null
harnesses=(scene_json mesh mask trajectory cli)
[ -n "${3:-}" ] && IFS=, read -r -a harnesses <<<"$3"
cmake --build "$build" -j"$(nproc)" --target "${harnesses[@]/#/pvr_fuzz_}" >/dev/null

models=/usr/share/assimp/models
seed() {  # harness, files...
  local dir=$build/corpus/$1
  shift
  mkdir -p "$dir"
  for f in "$@"; do [ -f "$f" ] && cp "$f" "$dir/$(echo "$f" | md5sum | cut -c1-12)-$(basename "$f")"; done
  return 0
}
seed scene_json tests/data/*.json scenes/*.json
seed mesh tests/data/*.obj tests/data/*.gltf $(find "$models/glTF2" $models/invalid $models/OBJ \
  \( -name '*.gltf' -o -name '*.glb' -o -name '*.obj' \) -size -40k 2>/dev/null | sort)
seed mask tests/fuzz/corpus/mask/*
seed trajectory tests/data/*.traj
seed cli tests/fuzz/corpus/cli/*
export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1
export LSAN_OPTIONS=suppressions=$PWD/tests/sanitizers/lsan.supp:print_suppressions=0
failures=0
for h in "${harnesses[@]}"; do
  mkdir -p "$build/artifacts/$h"
  [ -d "tests/fuzz/regressions/$h" ] && seed "$h" tests/fuzz/regressions/"$h"/*
  log=$build/fuzz_$h.log
  rc=0
  extra=()
  [ "$fork" -gt 1 ] && extra=(-fork="$fork")
  "$build/tests/pvr_fuzz_$h" -max_total_time="$seconds" -timeout=1 -rss_limit_mb=2560 -print_final_stats=1 "${extra[@]}" \
    -artifact_prefix="$build/artifacts/$h/" "$build/corpus/$h" >"$log" 2>&1 || rc=$?
  # One process prints its total; under -fork the parent's last "#N" line counts all workers.
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1 || true)
  [ -n "$runs" ] || runs=$(grep -o '^#[0-9]*' "$log" | tr -d '#' | sort -n | tail -1 || true)
  runs=${runs:-0}
  found=$(find "$build/artifacts/$h" -type f | wc -l)
  echo "fuzz $h: $runs executions in ${seconds} s, corpus $(find "$build/corpus/$h" -type f | wc -l) inputs," \
    "$found finding(s), exit $rc"
  if [ "$rc" -ne 0 ] || [ "$found" -ne 0 ]; then
    failures=$((failures + 1))
    grep -m3 -E 'ERROR|SUMMARY|leak|timeout' "$log" || true
  fi
done
[ $failures -eq 0 ]
