#!/usr/bin/env bash
# The desktop viewer under Xvfb on the CPU backend: it opens, renders the Cornell box, writes a
# screenshot on a scripted F12 and exits on a scripted Escape. What each eye shows is read back
# from its Vulkan image; it must be byte for byte the PNG that `render` writes from the settings
# file the viewer wrote (same pose, same options).
set -u
exe=$1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
command -v xvfb-run >/dev/null || fail "xvfb-run is not installed (package xvfb)"
# Traced first hits, then the G-buffer pre-pass (a second Vulkan device of the viewer's process),
# then traced with the density disc clipped at walls (the panel's checkbox, kept in the settings).
for run in rays:sphere raster:sphere rays:clipped; do
  mode=${run%%:*} boundary=${run##*:}
  # Our own X authority file, not xvfb-run's temporary directory (whose removal can fail: exit 5).
  timeout 120 xvfb-run -a -f "$out/xauthority" -s "-screen 0 1024x768x24" "$exe" view --backend cpu --eye-size 64x72 --photons 64x64 \
    --primary $mode --boundary $boundary --keys 2:F12,4:Escape --screenshot "$out/shot" >"$out/log" 2>&1
  rc=$?
  cat "$out/log"
  [ $rc -eq 0 ] || fail "viewer ($mode) exit code $rc"
  for f in shot_left.png shot_right.png shot.json shot_window.png; do [ -s "$out/$f" ] || fail "no $f written ($mode)"; done
  grep -q '"scene": "cornell"' "$out/shot.json" || fail "settings file lacks the scene"
  grep -q "\"primary\": \"$mode\"" "$out/shot.json" || fail "settings file lacks the primary visibility ($mode)"
  grep -q "\"boundary\": \"$boundary\"" "$out/shot.json" || fail "settings file lacks the boundary ($boundary)"
  "$exe" render --settings "$out/shot.json" --out "$out/render" >"$out/render.log" 2>&1 || fail "render --settings failed: $(cat "$out/render.log")"
  cmp "$out/render_left.png" "$out/shot_left.png" || fail "left eye differs from render's image ($mode)"
  cmp "$out/render_right.png" "$out/shot_right.png" || fail "right eye differs from render's image ($mode)"
  rm -f "$out"/shot* "$out"/render*
done
echo "viewer ok: both eyes match render's PNGs byte for byte, traced and rasterised first hits, clipped boundary"
