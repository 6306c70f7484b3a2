#!/usr/bin/env bash
# snell-view over many frames, switching scenes every EVERY frames (the eye at
# two resolutions, animated): each time a scene comes back, the GPU memory in
# use must be what it was the time before, and host memory must not creep.
#   viewer_soak.sh SNELL SNELL_VIEW FRAMES EVERY [JSON] [HOST_MIB]
# HOST_MIB (default 16) bounds the host's growth from a scene's second visit to
# its last; the validation layer's own bookkeeping grows with every scene
# loaded, so a run with SNELL_VALIDATION=1 reports the growth it finds.
set -euo pipefail
snell=$1 view=$2 frames=$3 every=$4 json=${5:-} hostLimit=${6:-16}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$snell" eye -o "$dir/eye.glb" >/dev/null
"$snell" eye --resolution 24 -o "$dir/eye-low.glb" >/dev/null
{
  echo "0 play"
  for ((f = every; f < frames; f += every)); do
    if (((f / every) % 2)); then echo "$f load $dir/eye-low.glb"; else echo "$f load $dir/eye.glb"; fi
  done
} >"$dir/soak.script"
args=(--offscreen --size 64x48 --frames "$frames" --script "$dir/soak.script")
[[ -n $json ]] && args+=(--json "$json")
start=$(date +%s)
if ! "$view" "${args[@]}" >"$dir/log" 2>&1; then
  tail -30 "$dir/log"
  echo "viewer_soak: snell-view failed" >&2
  exit 1
fi
grep -E "^memory at frame|frames in" "$dir/log"
# Lines: memory at frame N (SCENE): host H MiB resident, GPU G MiB in use
awk -v seconds=$(($(date +%s) - start)) -v hostLimit="$hostLimit" '
  /^memory at frame/ {
    scene = $5; sub(/^\(/, "", scene); sub(/\):$/, "", scene); sub(/.*\//, "", scene)
    host = $7; gpu = $11; n[scene]++
    if (n[scene] == 2) { firstHost[scene] = host }
    if (n[scene] >= 2 && gpu != lastGpu[scene]) { bad = bad "\n  " scene ": GPU " lastGpu[scene] " MiB then " gpu " MiB" }
    lastGpu[scene] = gpu; lastHost[scene] = host; samples++
  }
  END {
    worst = 0
    for (s in n) if (n[s] >= 3) { g = lastHost[s] - firstHost[s]; if (g > worst) worst = g }
    printf "viewer_soak: %d samples in %d s; GPU memory the same each time a scene returns: %s; host growth from a scene'"'"'s second visit to its last: %.1f MiB at most\n", samples, seconds, bad == "" ? "yes" : "NO" bad, worst
    if (bad != "" || worst > hostLimit) exit 1
  }' "$dir/log"
