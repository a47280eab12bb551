#!/usr/bin/env bash
# Bad input through the real photonvr executable: each case must exit non-zero (not by a
# signal), print exactly one line on stderr, and that line must name the problem.
set -u
exe=$1
data=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
failures=0
small=(--eye-size 8x8 --photons 16x16 --out "$out/img")

expect_error() {  # expected-substring, arguments...
  local expected=$1
  shift
  "$exe" "$@" >"$out/stdout" 2>"$out/stderr"
  local rc=$?
  local lines
  lines=$(wc -l <"$out/stderr")
  if [ "$rc" -eq 0 ] || [ "$rc" -ge 128 ]; then
    echo "FAIL ($*): exit code $rc"
    failures=$((failures + 1))
  elif [ "$lines" -ne 1 ]; then
    echo "FAIL ($*): $lines lines on stderr:"
    cat "$out/stderr"
    failures=$((failures + 1))
  elif ! grep -qi -- "$expected" "$out/stderr"; then
    echo "FAIL ($*): expected '$expected' in: $(cat "$out/stderr")"
    failures=$((failures + 1))
  else
    echo "ok   ($*): $(cat "$out/stderr")"
  fi
}

expect_error "no such file" render "$data/missing.gltf" "${small[@]}"
expect_error "unsupported scene format" render "$data/not_a_scene.txt" "${small[@]}"
expect_error "malformed JSON" render "$data/malformed.json" "${small[@]}"
expect_error "cannot read" render "$data/malformed.gltf" "${small[@]}"
expect_error "no light" render "$data/no_light.json" "${small[@]}"
echo '{"base": "cornell", "lights": [{"sky": [-1, 0, 0]}]}' >"$out/negative_sky.json"
expect_error "radiance must not be negative" render "$out/negative_sky.json" "${small[@]}"
echo '{"base": "cornell", "lights": [{"sky": [1, 1, 1], "aim_radius": 2}]}' >"$out/half_aimed_sky.json"
expect_error "needs both aim_center and aim_radius" render "$out/half_aimed_sky.json" "${small[@]}"
echo "{\"base\": \"cornell\", \"meshes\": [{\"file\": \"$data/box.obj\", \"use_camera\": true}]}" >"$out/no_camera.json"
expect_error "has no camera to use" render "$out/no_camera.json" "${small[@]}"
echo "{\"base\": \"cornell\", \"meshes\": [{\"file\": \"$data/box.obj\", \"use_camera\": 1}]}" >"$out/camera_flag.json"
expect_error "use_camera must be true or false" render "$out/camera_flag.json" "${small[@]}"
expect_error "photons must be" render cornell --photons 0 --eye-size 8x8
expect_error "--backend must be" render cornell --backend gpu --eye-size 8x8
expect_error "--kernel must be" render cornell --kernel fused --eye-size 8x8
expect_error "works on the hash grid" render cornell --kernel shared --map kdtree --eye-size 8x8
expect_error "--stereo must be" render cornell --stereo both --eye-size 8x8
expect_error "needs both eyes" render cornell --stereo gather --eyes left --eye-size 8x8
expect_error "--stereo must be" bench --suite stereo --backend cpu --stereo mirror --eye-size 8x8 --frames 1
expect_error "--acuity must be" mask --acuity eagle --out "$out/m.pvrmask"
expect_error "--margin must be" mask --margin -2 --out "$out/m.pvrmask"
expect_error "--eye-size" mask --eye-size 0x5 --out "$out/m.pvrmask"
expect_error "cannot write" mask --eye-size 32x32 --out /dev/null/m.pvrmask
expect_error "--gaze: the gaze must lie in the image" render cornell --foveated --gaze 2,0.5 --eye-size 8x8
expect_error "--gaze must be" render cornell --foveated --gaze 0.5 --eye-size 8x8
expect_error "cannot open mask file" render cornell --foveated --mask "$data/missing.pvrmask" --eye-size 8x8
expect_error "not a photonvr mask" render cornell --foveated --mask "$data/box.obj" --eye-size 8x8
expect_error "only for\|is for --foveated" render cornell --mask "$data/box.obj" --eye-size 8x8
"$exe" mask --eye-size 32x32 --out "$out/m32.pvrmask" >/dev/null 2>&1
expect_error "mask is for 32x32" render cornell --foveated --mask "$out/m32.pvrmask" --eye-size 16x16
expect_error "cannot open trajectory" render cornell --trajectory "$data/missing.txt" --eye-size 8x8
expect_error "line 2: .mtllib. is not a number" render cornell --trajectory "$data/box.obj" --eye-size 8x8
expect_error "--taa-blend is for --taa" render cornell --taa-blend 0.5 --eye-size 8x8
expect_error "--taa-blend: the TAA blend must be in (0, 1\]" render cornell --taa --taa-blend 0 --eye-size 8x8
expect_error "--taa-blend: the TAA blend must be in (0, 1\]" render cornell --taa --taa-blend 1.5 --eye-size 8x8
expect_error "--taa-blend" render cornell --taa --taa-blend nan --eye-size 8x8
expect_error "--taa-blend" render cornell --taa --taa-blend 0.5x --eye-size 8x8
expect_error "--denoise-iterations is for --denoise" render cornell --denoise-iterations 3 --eye-size 8x8
expect_error "--no-refine is for --denoise" render cornell --no-refine --eye-size 8x8
expect_error "--denoise-history is for --denoise" render cornell --denoise-history bilinear --eye-size 8x8
expect_error "--denoise-history must be catmull-rom or bilinear, got 'cubic'" render cornell --denoise --denoise-history cubic --eye-size 8x8
expect_error "--denoise-photon-passes is for --denoise" render cornell --denoise-photon-passes quarter --eye-size 8x8
expect_error "--denoise-photon-passes must be full or quarter, got 'half'" render cornell --denoise --denoise-photon-passes half --eye-size 8x8
expect_error "--denoise-iterations: the denoiser's a-trous passes must be between 0 and 8" render cornell --denoise --denoise-iterations 9 --eye-size 8x8
expect_error "--denoise-iterations: the denoiser's a-trous passes must be between 0 and 8" render cornell --denoise --denoise-iterations -1 --eye-size 8x8
expect_error "--denoise-iterations" render cornell --denoise --denoise-iterations two --eye-size 8x8
expect_error "--denoise-direct-iterations is for --denoise" render cornell --denoise-direct-iterations 2 --eye-size 8x8
expect_error "--denoise-direct-iterations: the direct signal's a-trous passes must be between 1 and 8" render cornell --denoise --denoise-direct-iterations 0 --eye-size 8x8
expect_error "--denoise-direct-iterations: the direct signal's a-trous passes must be between 1 and 8" render cornell --denoise --denoise-direct-iterations 9 --eye-size 8x8
expect_error "--photon-batches: the photon batches must be between 1 and 64, and at most the photons" render cornell --photon-batches 0 --eye-size 8x8
expect_error "--photon-batches: the photon batches must be between 1 and 64, and at most the photons" render cornell --photon-batches 65 --eye-size 8x8
expect_error "--photon-batches: the photon batches must be between 1 and 64, and at most the photons" render cornell --photons 4x4 --photon-batches 32 --eye-size 8x8
expect_error "--density must be pixel or cache" render cornell --backend cpu --density fast "${small[@]}"
expect_error "--cache-cell: the surface cache's cell must be between" render cornell --backend cpu --density cache --cache-cell 2 "${small[@]}"
expect_error "--cache-cell: the surface cache's cell must be between" render cornell --backend cpu --density cache --cache-cell nan "${small[@]}"
expect_error "--density: the surface cache shades full-resolution eyes" render cornell --backend cpu --density cache --foveated "${small[@]}"
expect_error "--primary must be rays or raster" render cornell --backend cpu --primary gbuffer "${small[@]}"
expect_error "--boundary must be sphere or clipped" render cornell --backend cpu --boundary planes "${small[@]}"
expect_error "--density: the surface cache's cells mix points on both sides of a wall" render cornell --backend cpu --density cache --boundary clipped "${small[@]}"
# The pre-pass without any Vulkan driver (the loader finds none): one line, before any frame.
VK_DRIVER_FILES=/nonexistent/icd.json VK_ICD_FILENAMES=/nonexistent/icd.json \
  expect_error "--primary raster: no Vulkan driver found" render cornell --backend cpu --primary raster "${small[@]}"
# Effect groups and the budget controller.
expect_error "no effect group 'statues' (it has: rest, specular)" render cornell-caustics --backend cpu --effects statues=gi "${small[@]}"
expect_error "is not GROUP=LEVEL" render cornell-caustics --backend cpu --effects specular=shiny "${small[@]}"
expect_error "is not GROUP=LEVEL" render cornell-caustics --backend cpu --effects specular=gi,rest "${small[@]}"
expect_error "--budget-ms is for --trajectory" render cornell --backend cpu --budget-ms 11.1 "${small[@]}"
printf '0 0.5 1  0 0 0 1  0.5 0.5\n' >"$out/one.traj"
expect_error "--budget-ms must be a positive number" render cornell --backend cpu --budget-ms -2 --trajectory "$out/one.traj" "${small[@]}"
expect_error "--budget-ms must be a positive number" render cornell --backend cpu --budget-ms nan --trajectory "$out/one.traj" "${small[@]}"
expect_error "--budget-ms must be a positive number of milliseconds (at most 10000) or 'display'" render cornell --backend cpu \
  --budget-ms 11ms --trajectory "$out/one.traj" "${small[@]}"
expect_error "--budget-ms display needs a display" render cornell --backend cpu --budget-ms display --trajectory "$out/one.traj" "${small[@]}"
expect_error "cannot open controller profile" render cornell --backend cpu --budget-ms 11.1 --controller-profile "$out/none.json" \
  --trajectory "$out/one.traj" "${small[@]}"
echo '{"error": {"top": 0.1}}' >"$out/short_profile.json"
expect_error "controller profile '$out/short_profile.json'" render cornell --backend cpu --budget-ms 11.1 \
  --controller-profile "$out/short_profile.json" --trajectory "$out/one.traj" "${small[@]}"
expect_error "--profile-out is for --suite effects or controller" bench --suite tables --profile-out "$out/p"
expect_error "--walks must name SCENE=TRAJECTORY" bench --suite controller --backend cpu
expect_error "--budgets must be" bench --suite controller --backend cpu --walks "cornell=$out/one.traj" --budgets 5,x
expect_error "fewer than the first sampled view's 136" bench --suite controller --backend cpu --walks "cornell=$out/one.traj" \
  --eye-size 8x8 --error-every 270 --fixed-stride 9
expect_error "--suite must be tables, stereo, foveation, scenes, quality" bench --suite qualty
expect_error "--reference-passes must be between 2" bench --suite quality --reference-passes 1 --backend cpu
expect_error "--quality-variants: no variant 'denoised'" bench --suite quality --quality-variants "denoise;denoised" --backend cpu
expect_error "--suite must be" bench --suite speed
expect_error "--frames must be" bench --suite tables --frames 0
expect_error "--tables takes" bench --suite tables --backend cpu --tables 5 --eye-size 8x8 --frames 1
expect_error "photons must be" render cornell --photons 0x256 --eye-size 8x8
expect_error "photons" render cornell --photons -5 --eye-size 8x8
expect_error "--photons: too many photons" render cornell --photons 100000x100000 --eye-size 8x8
expect_error "radius" render cornell --radius 0 --eye-size 8x8
expect_error "radius" render cornell --radius -0.1 --eye-size 8x8
expect_error "radius" render cornell --radius nan --eye-size 8x8
expect_error "radius" render cornell --radius inf --eye-size 8x8
expect_error "radius" render cornell --radius abc --eye-size 8x8
expect_error "eye-size" render cornell --eye-size 0x0
expect_error "eye-size" render cornell --eye-size 100000x100000
expect_error "eye-size" render cornell --eye-size 12
expect_error "--ipd: the IPD must be" render cornell --ipd -1 --eye-size 8x8
expect_error "--ipd: the IPD must be" render cornell --ipd inf --eye-size 8x8
expect_error "--spp: samples per pixel" render cornell --spp 5000 --eye-size 8x8
expect_error "--photon-depth: the photon depth" render cornell --photon-depth 0 --eye-size 8x8
expect_error "--specular-depth: the specular depth" render cornell --specular-depth 65 --eye-size 8x8
expect_error "--shadow-rays: the shadow rays per point" render cornell --shadow-rays -1 --eye-size 8x8
expect_error "--shadow-rays: the shadow rays per point" render cornell --shadow-rays 65 --eye-size 8x8
ref=(reference cornell --backend cpu --eye-size 8x8 --photons 16x16 --out "$out/ref")
expect_error "--passes must be between 1" "${ref[@]}" --passes 0
expect_error "--alpha must be between 0 and 1" "${ref[@]}" --alpha 1
expect_error "--filter must be box or centre" "${ref[@]}" --filter gauss
expect_error "--frame is for --trajectory" "${ref[@]}" --frame 2
expect_error "--frame 9 is past the trajectory" "${ref[@]}" --trajectory "$data/gaze_pursuit.traj" --frame 9
expect_error "not expected: --foveated" "${ref[@]}" --foveated
expect_error "no such file" "${ref[@]}" --passes 1 --compare "$out/missing"
printf 'not an exr' >"$out/bad_left.exr"
expect_error "as EXR" "${ref[@]}" --passes 1 --eyes left --compare "$out/bad"
expect_error "--photons: too many photons" render cornell --photons 8193x8192 --eye-size 8x8
expect_error "--k" render cornell --estimator knn --k 0 --eye-size 8x8
expect_error "--k" render cornell --estimator knn --k 65 --eye-size 8x8
expect_error "--map" render cornell --map octree --eye-size 8x8
expect_error "--estimator" render cornell --estimator gaussian --eye-size 8x8
expect_error "--eyes" render cornell --eyes middle --eye-size 8x8
expect_error "--spp" render cornell --spp 0 --eye-size 8x8
expect_error "cannot" render cornell --eye-size 8x8 --photons 16x16 --out /dev/null/img
expect_error "radius 1e-05 is too small" render cornell --radius 0.00001 --eye-size 8x8
expect_error "the following argument was not expected\|extraneous\|not expected" render cornell extra-positional
expect_error "" render cornell --no-such-option
expect_error "" frobnicate
expect_error "" bench cornell --k 0

# The frame loop's commands: no runtime, no display, bad loop options, bad settings files.
XR_RUNTIME_JSON="$out/no-such-runtime.json" expect_error "no OpenXR runtime" xr --backend cpu --frames 1
DISPLAY= WAYLAND_DISPLAY= expect_error "no display" view --backend cpu --eye-size 8x8
expect_error "--keys entries are FRAME:KEY" view --backend cpu --keys F12
expect_error "unknown key" view --backend cpu --keys 3:F13
expect_error "--handover must be" xr --offscreen --backend cpu --eye-size 8x8 --photons 16x16 --frames 1 --handover pcie --stats ""
expect_error "refresh rate" xr --offscreen --backend cpu --eye-size 8x8 --photons 16x16 --frames 1 --refresh 0 --stats ""
VK_DRIVER_FILES="$out/none.json" VK_ICD_FILENAMES="$out/none.json" expect_error "no Vulkan driver" xr --offscreen --backend cpu --eye-size 8x8 --photons 16x16 --frames 1 --stats ""
expect_error "--cuda-copy must be" xr --offscreen --backend cpu --cuda-copy dma --frames 1
expect_error "--near must be" xr --offscreen --backend cpu --near -1 --frames 1
expect_error "--ready-timeout must be" xr --backend cpu --ready-timeout 0 --frames 1
expect_error "cannot read settings file" render --settings "$out/none.json" "${small[@]}"
expect_settings_error() {  # expected-substring, the settings file's text
  printf '%s\n' "$2" >"$out/settings.json"
  expect_error "$1" render --settings "$out/settings.json" "${small[@]}"
}
expect_settings_error "not valid JSON" '{"radius": '
expect_settings_error "must hold a JSON object" '[1, 2]'
expect_settings_error "wrong type or is missing" '{"head": {"position": [0, 1], "orientation": [0, 0, 0, 1]}}'
expect_settings_error "non-zero quaternion" '{"head": {"position": [0, 1, 2], "orientation": [0, 0, 0, 0]}}'
expect_settings_error "radius" '{"radius": "-1"}'
# Numbers outside the type they fill: an error naming the key, never a cast (undefined there).
expect_settings_error "k must be an integer" '{"k": 1e20}'
expect_settings_error "denoise_iterations must be an integer" '{"denoise_iterations": 2.5}'
expect_settings_error "denoise_direct_iterations must be an integer" '{"denoise_direct_iterations": 1e20}'
expect_settings_error "exposure must be a finite number" '{"exposure": 1e300}'
expect_settings_error "the head pose must be a finite number" '{"head": {"position": [0, 1e39, 0], "orientation": [0, 0, 0, 1]}}'
expect_error "--acuity must be" render cornell --foveated --acuity sharp "${small[@]}"

# NaN vertices and degenerate triangles: a warning, and the render goes on.
"$exe" render "$data/nan_and_degenerate.obj" "${small[@]}" >"$out/stdout" 2>"$out/stderr"
rc=$?
if [ "$rc" -ne 0 ] || ! grep -q "skipped 2 degenerate or non-finite triangles" "$out/stderr"; then
  echo "FAIL (nan_and_degenerate.obj): exit $rc, stderr: $(cat "$out/stderr")"
  failures=$((failures + 1))
else
  echo "ok   (nan_and_degenerate.obj): $(cat "$out/stderr")"
fi

# Input limits (pvr/util/input_limits.h; the others are tested with lowered limits in pvr_tests).
yes "0 0 0 0 0 0 1 0.5 0.5" 2>/dev/null | head -n 1000001 >"$out/long.traj"
expect_error "has more than 1000000 frames: at most 1000000" render cornell "${small[@]}" --trajectory "$out/long.traj"
rm -f "$out/long.traj"

# The soak's arguments.
soak=(soak cornell --backend cpu --eye-size 8x8 --photons 16x16 --json "$out/soak.json")
expect_error "at least three cycles" "${soak[@]}" --frames 20 --change-every 1
expect_error "multiple of the options' cycle" "${soak[@]}" --frames 60 --change-every 2 --reload-every 30
expect_error "change-every must be between" "${soak[@]}" --change-every 0
expect_error "at most 100000000 frames" "${soak[@]}" --frames 1000000000
expect_error "max-rss-growth must be" "${soak[@]}" --frames 60 --change-every 2 --max-rss-growth -1
expect_error "empty scene name" "${soak[@]}" --frames 60 --change-every 2 --reload-scenes cornell,,cornell

[ "$failures" -eq 0 ] && echo "all bad-input cases passed" || echo "$failures bad-input case(s) failed"
exit $((failures > 0))
