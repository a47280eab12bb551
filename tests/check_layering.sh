#!/usr/bin/env bash
# The folders under src/pvr depend one way: each may include only the folders listed for it (and
# itself). A new include that runs back up (a stage reaching into the pipeline, the pipeline into
# a backend) fails here, with the file and the include.
set -u
src=${1:-$(dirname "$0")/../src}/pvr
declare -A allowed=(
  [math]=""
  [util]="math"
  [geometry]="math"
  [camera]="geometry math"
  [shading]="geometry math util"
  [scene]="shading camera geometry math util"
  [stereo]="camera shading geometry math util"
  [photon]="stereo shading camera geometry math util"
  [image]="math util"
  [foveation]="stereo image camera geometry math util"
  [temporal]="stereo image camera geometry math util"
  [denoise]="temporal stereo image camera geometry math util"
  [accel]="scene shading camera geometry math util"
  [vulkan]="math util"
  [raster]="vulkan scene shading camera geometry math util"
  [pipeline]="photon stereo foveation denoise temporal image scene shading camera geometry math util"
  [cpu]="raster vulkan pipeline photon stereo foveation denoise temporal image scene shading camera geometry math util"
  [cuda]="raster vulkan pipeline accel photon stereo foveation denoise temporal image scene shading camera geometry math util"
  [reference]="pipeline photon stereo foveation denoise temporal image scene shading camera geometry math util"
  [render]="raster vulkan cpu cuda pipeline photon stereo foveation denoise temporal image scene shading camera geometry math util"
  [control]="pipeline photon stereo foveation denoise temporal image scene shading camera geometry math util"
  [loop]="control render raster vulkan pipeline photon stereo foveation denoise temporal image scene shading camera geometry math util"
  [vk]="vulkan loop cuda image geometry math util"
  [xr]="control vulkan raster loop vk render cuda pipeline photon stereo foveation denoise temporal image scene shading camera geometry math util"
  [viewer]="control vulkan raster loop vk render cuda pipeline photon stereo foveation denoise temporal image scene shading camera geometry math util"
  [app]="control viewer xr vk vulkan raster loop render reference cpu cuda pipeline accel photon stereo foveation denoise temporal image scene shading camera geometry math util"
)
failures=0
for dir in "$src"/*/; do
  folder=$(basename "$dir")
  if [ -z "${allowed[$folder]+set}" ]; then
    echo "FAIL: src/pvr/$folder has no place in the layering (add it to tests/check_layering.sh)"
    failures=$((failures + 1))
    continue
  fi
  while IFS=: read -r file _ include; do
    target=$(sed -E 's|.*"pvr/([^/"]+)/.*|\1|' <<<"$include")
    [ "$target" = "$folder" ] && continue
    if ! grep -qw -- "$target" <<<"${allowed[$folder]}"; then
      echo "FAIL: ${file#"$src"/} includes pvr/$target/ (src/pvr/$folder may include only: ${allowed[$folder]:-nothing})"
      failures=$((failures + 1))
    fi
  done < <(grep -rn '#include "pvr/[^/"]*/' "$dir")
done
echo "$failures layering violation(s)"
[ $failures -eq 0 ]
