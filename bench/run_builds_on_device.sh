#!/usr/bin/env bash
# Issue 40 on the lent NVIDIA machine (see ../.library/device): several builds
# of snell side by side in one lease. Set up as bench/run_frame_on_device.sh
# (binaries in .carry/, Debian libraries in .carry/lib, the validation layer
# in .carry/layer, the Vulkan loader in .gl/); the builds measured are
# .carry/snell-<name> for each name in BUILDS (default: base step1 wide), and
# the test binary .carry/snell_tests.
#   bench/run_builds_on_device.sh tests    # the tree's, trace's and images' tests, validation on
#   bench/run_builds_on_device.sh same     # each build's pixel hashes of the three trace scenes (bit-identical changes)
#   bench/run_builds_on_device.sh cost     # bench cost (segments, visits, tests, hit replay), spheres, wedges, eye
#   bench/run_builds_on_device.sh trace    # trace against driver-rt at 1920x1080: spheres of 100k and 1M, the eye,
#                                          # and the 1M sphere as ten instanced wedges (the footprint ablation)
#   bench/run_builds_on_device.sh build    # bench scale at 1M: build (with its steps) and refit beside the driver's
#   bench/run_builds_on_device.sh viewport # the viewport's refraction work: crowd 2, eye 64, eye 256, crowd 100 at 4K
# A build name may carry a leaf size, for the 8-wide tree's patch (git show 31fafc1:bench/experiments/wide-bvh8.patch):
# wide@1 runs .carry/snell-wide with SNELL_BVH_LEAF_MAX=1.
set -uo pipefail
source "$(dirname "$0")/device_env.sh"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.mem --format=csv,noheader
read -r -a builds <<<"${BUILDS:-base step1 wide}"
step=${1:-trace}
scenes=/tmp/scenes
mkdir -p $scenes
[[ -f $scenes/sphere-100k.gltf ]] || {
  python3 bench/make_sphere.py 100000 $scenes/sphere-100k.gltf
  python3 bench/make_sphere.py 1000000 $scenes/sphere-1m.gltf
  python3 bench/make_sphere.py 1000000 $scenes/sphere-1m-wedges.gltf 10
} >/dev/null
# Runs build $1 (name[@leaf size]) with the rest of the arguments.
run() {
  local name=${1%@*} leaf=
  [[ $1 == *@* ]] && leaf=${1#*@}
  shift
  SNELL_BVH_LEAF_MAX=$leaf ".carry/snell-$name" "$@"
}
scene() { [[ $1 == eye ]] && echo "" || echo "$scenes/$1.gltf"; }
json=$(mktemp -d)
case $step in
  tests)
    mkdir -p build/device && ln -sf "$PWD/.carry/snell-${builds[-1]%@*}" build/device/snell
    # The tree's tests, the goldens, the stability grid and the corrupted tree, validation on (the others
    # need the carried assets or the CLI's path). Every test makes its own device: the pipeline caches
    # keep them from compiling the trace again each time.
    export SNELL_PIPELINE_CACHE=/tmp/caches/snell __GL_SHADER_DISK_CACHE_PATH=/tmp/caches/nv
    mkdir -p /tmp/caches/snell /tmp/caches/nv
    SNELL_VALIDATION=1 timeout 200 .carry/snell_tests \
      --gtest_filter='BvhTest.*:Images/Golden.*:Grid/StressGrid.*:StressLimits.*' >"$OUT/tests.log" 2>&1
    echo "tests exit $?"
    grep -E "^\[  (FAILED|PASSED) |tests? ran" "$OUT/tests.log" | tail -12
    ;;
  same)
    for b in "${builds[@]}"; do
      for s in sphere-100k sphere-1m eye; do
        args=$(scene $s)
        [[ -z $args ]] && args=--eye
        run "$b" -q render $args --method trace --size 1920x1080 -o "/tmp/$s-$b.png" --stats-json "$json/$s-$b.json" \
          >/dev/null 2>&1
        echo "$s $b $(grep -o '"image_hash": *"[^"]*"' "$json/$s-$b.json")"
      done
    done | tee "$OUT/same.log"
    ;;
  cost)
    for s in sphere-100k sphere-1m sphere-1m-wedges eye; do
      for b in "${builds[@]}"; do
        echo "== $s, $b"
        run "$b" bench cost $(scene $s) --frames 20 --json "$json/cost-$s-$b.json" | tail -9
      done
    done 2>&1 | tee "$OUT/cost.log"
    ;;
  trace)
    for s in sphere-100k sphere-1m eye sphere-1m-wedges; do
      for b in "${builds[@]}"; do
        echo "== $s, $b"
        run "$b" bench methods $(scene $s) --methods trace,driver-rt --no-reference --frames 8 --size 1920x1080 \
          --json "$json/trace-$s-$b.json" | grep -E "^trace |^driver-rt |rays per second"
      done
    done 2>&1 | tee "$OUT/trace.log"
    ;;
  build)
    for b in "${builds[@]}"; do
      echo "== $b"
      run "$b" bench scale --crowds 0 --triangles 1000000 --json "$json/scale-$b.json" | tail -4
    done 2>&1 | tee "$OUT/build.log"
    ;;
  viewport)
    for b in "${builds[@]}"; do
      echo "== $b"
      run "$b" bench frame --crowd 2 --viewport --warmup 200 --json "$json/frame-crowd2-$b.json"
      run "$b" bench frame --viewport --warmup 200 --json "$json/frame-eye64-$b.json"
      run "$b" bench frame --eye-resolution 256 --viewport --warmup 200 --json "$json/frame-eye256-$b.json"
      run "$b" bench frame --crowd 100 --viewport --size 3840x2160 --warmup 100 --json "$json/frame-crowd100-4k-$b.json"
    done 2>&1 | grep -E "==|scene:|^refraction|^frame " | tee "$OUT/viewport.log"
    ;;
esac
tar -C "$json" -cf "$OUT/$step-results.tar" .
