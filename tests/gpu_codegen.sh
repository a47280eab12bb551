#!/usr/bin/env bash
# The ray kernels' code, checked without a GPU: compiles tests/codegen/traversal_kernels.cu to PTX
# with line info and fails if the traversal code (src/pvr) of a ray kernel loads or stores local
# memory anywhere but the local-stack fallback (a source line naming localStack). Such accesses ran every node visit
# through local memory (the binary BVH lost 2-4x of its ray rate to them, 2026-12-05).
#   usage: gpu_codegen.sh NVCC SOURCE_DIR
set -u
nvcc=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$nvcc" -std=c++17 -O3 -lineinfo -arch=compute_90 -ptx -DPVR_HAVE_CUDA=1 -I"$src/src" \
  "$src/tests/codegen/traversal_kernels.cu" -o "$out/k.ptx" || { echo "nvcc failed"; exit 1; }
# Each local access of an .entry, with the source line it belongs to.
awk -v srcdir="$src" '
  /^[ \t]*\.file[ \t]/ { f = $3; gsub(/"/, "", f); sub(/,$/, "", f); file[$2] = f; next }
  /\.entry[ \t]/ { entry = 1; next }
  /^\.func|[ \t]\.func[ \t]/ { entry = 0; next }
  /^[ \t]*\.loc[ \t]/ { loc = $2 ":" $3; next }
  entry && /(ld|st)\.local/ { n[loc]++ }
  END { for (l in n) { split(l, p, ":"); print file[p[1]] "\t" p[2] "\t" n[l] } }
' "$out/k.ptx" >"$out/locals.tsv"
entries=$(grep -c '\.entry' "$out/k.ptx")
[ "$entries" -eq 4 ] || { echo "expected 4 kernels in the PTX, found $entries"; exit 1; }
bad=0
while IFS=$'\t' read -r file line count; do
  # The kernels' own lines (copies made for the wide traversal's out-of-line call) are not checked.
  [[ $file == */src/pvr/* ]] || continue
  text=$(sed -n "${line}p" "$file" 2>/dev/null)
  if [[ $text == *localStack* ]]; then continue; fi
  echo "local memory: $count access(es) at $(basename "$file"):$line: $(echo "$text" | sed 's/^ *//')"
  bad=$((bad + 1))
done <"$out/locals.tsv"
fallback=$(cut -f1,2 "$out/locals.tsv" | while IFS=$'\t' read -r f l; do sed -n "${l}p" "$f"; done | grep -c localStack)
echo "$entries kernels: $fallback local-stack fallback line(s), $bad traversal line(s) with other local accesses"
[ $bad -eq 0 ]
