# Sourced by a device script (run on the GPU machine from the repository root, `run` with carry
# [".gpu", ".gl", ".scenes"]): unpacks the bundled binaries (.gpu/bin.tar.xz, from
# ../shared/gpu/bundle.sh with bin/ packed by xz), installs the Vulkan/EGL loader debs in .gl/,
# points PVR_SCENES at .scenes/, and defines
#   step NAME SECONDS COMMAND...   runs COMMAND with a time limit into $OUT/r/NAME.txt, appends
#                                  "NAME rc=RC SECONDS s" to $OUT/r/steps.txt and packs $OUT/r
# so that whatever ran comes back even if the call's time ends (at most 8 files come back: the
# results travel as $OUT/results.tgz).
tar -C .gpu -xJf .gpu/bin.tar.xz
for deb in .gl/*.deb; do dpkg -x "$deb" /; done
ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
export PVR_SCENES=$PWD/.scenes PVR_REQUIRE_VULKAN=1
results=$OUT/r
mkdir -p "$results"
pack() { tar -C "$OUT" -czf "$OUT/results.tgz" r; }
trap pack EXIT
nvidia-smi --query-gpu=name,driver_version --format=csv > "$results/gpu.txt" 2>&1
step() {
  local name=$1 limit=$2 began=$SECONDS
  shift 2
  timeout "$limit" "$@" > "$results/$name.txt" 2>&1
  echo "$name rc=$? $((SECONDS - began)) s" | tee -a "$results/steps.txt"
  pack
}
