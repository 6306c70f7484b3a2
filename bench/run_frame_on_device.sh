#!/usr/bin/env bash
# Runs on the lent NVIDIA machine (see ../.library/device): the scale issue's
# measurements in one place. Binaries are built on the Debian machine without
# OpenImageIO or the viewer and carried in .carry/ (snell, snell_tests, their
# two Debian libraries in .carry/lib, the validation layer in .carry/layer);
# the Vulkan loader in .gl/; the shared glTF assets in .assets/.
#   bench/run_frame_on_device.sh tests   # the suite, validation on
#   bench/run_frame_on_device.sh bench   # bench scale, frame and bvh
#   bench/run_frame_on_device.sh methods # bench methods at 1920x1080, its chart
#   bench/run_frame_on_device.sh optics  # each optics feature's cost (1920x1080) and error (320x240), stress grid's optics group
#   bench/run_frame_on_device.sh textures # load times of the textured sample models (three runs each)
#   bench/run_frame_on_device.sh maps    # refraction-map beside the trace and the raster methods (1920x1080), drift table
#   bench/run_frame_on_device.sh robust  # the long runs: bench frame --soak (validation on) on the GPU while the
#                                        # libFuzzer targets (carried in .fuzz/) run on the other cores
#   bench/run_frame_on_device.sh first   # a first image in a fresh process: driver and snell caches empty, then warm
#   bench/run_frame_on_device.sh trace   # trace against driver-rt at 1920x1080: glass spheres of 100k and 1M
#                                        # triangles (bench/make_sphere.py), the eye
#   bench/run_frame_on_device.sh viewport # the viewport's refraction work: crowd 2, eye 64, eye 256, crowd 100 at 4K
#   bench/run_frame_on_device.sh build   # bench scale: build and refit of 1M and 10M triangles beside the driver's
#   bench/run_frame_on_device.sh farm    # CUDA_VISIBLE_DEVICES by index and UUID mapped to the Vulkan device,
#                                        # the frame-list, farm and device-mapping tests
#   bench/run_frame_on_device.sh shot    # (two GPUs) bench shot on one GPU and on both; CUDA_VISIBLE_DEVICES
#                                        # with --devices all; the multi-device tests on the GPUs
#   bench/run_frame_on_device.sh shot1   # (one GPU) the same code with two workers on the one GPU (--devices 0,0),
#                                        # SHOT_FRAMES (24) frames, and the multi-device tests
#   bench/run_frame_on_device.sh python  # the Python module, built there for its python3 against the carried
#                                        # install (.carry/prefix), replaying the Blender feed in .carry/feed
#                                        # (bench/record_blender_feed.py), beside bench frame of the rig's glTF
#   bench/run_frame_on_device.sh usd     # snell.usd's feed (bench/usd_feed.py) of the eye pair and its dense
#                                        # version (written here into .carry/usd-eyes and .carry/usd-dense by
#                                        # tests/usd/eye_stage.py), usd-core from .whl, the module built there as
#                                        # for python, beside bench frame of each stage's glTF twin
# SNELL_BIN picks another carried binary for the first, trace, viewport,
# build and shot1 steps (default .carry/snell), to measure two builds in one lease.
# Results land in $OUT.
set -uo pipefail
source "$(dirname "$0")/device_env.sh"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.mem --format=csv
step=${1:-all}
snell=${SNELL_BIN:-.carry/snell}
# The tests that run the command find it where it was built.
mkdir -p build/device && ln -sf "$PWD/.carry/snell" build/device/snell
if [[ $step == all || $step == tests ]]; then
  echo "== tests on the GPU, validation on (not the ones that run the CLI, the viewer or node)"
  SNELL_VALIDATION=1 .carry/snell_tests --gtest_brief=1 \
    --gtest_filter='-SnellCommand.*:SceneInfoCommand.*:RenderCommand.*:BenchMethods.*:BakeCommand.*:ExportWebCommand.*:Viewer.*:GlHost.*:ProceduralEye.PassesTheKhronos*' > "$OUT/tests.log" 2>&1
  echo "tests exit $?"; grep -E "FAILED|PASSED|tests ran" "$OUT/tests.log" | tail -12
fi
if [[ $step == robust ]]; then
  echo "== soak: bench frame --viewport --soak ${SOAK_SECONDS:-570}, validation on, in the background"
  ((${SOAK_SECONDS:-570} > 0)) && SNELL_VALIDATION=1 .carry/snell bench frame --viewport --soak "${SOAK_SECONDS:-570}" --json "$OUT/soak.json" \
    >"$OUT/soak.log" 2>&1 &
  soak=$!
  logs=$(mktemp -d)
  # The glTF targets (the CLI's links OpenImageIO, which is not carried: it runs on the Debian machine).
  for t in gltf evaluate info; do
    dict=.fuzz/gltf.dict
    corpus=/tmp/corpus-$t
    mkdir -p "$corpus"
    cp -r ".fuzz/corpus/$t/." "$corpus/" 2>/dev/null
    ASAN_OPTIONS=detect_leaks=1 ".fuzz/fuzz_$t" -fork="${FUZZ_JOBS:-13}" -ignore_crashes=1 -max_total_time="${FUZZ_SECONDS:-125}" \
      -max_len=65536 -timeout=10 -rss_limit_mb=2048 -dict="$dict" -artifact_prefix="$OUT/crash-$t-" \
      "$corpus" ".fuzz/seeds/$t" >"$logs/fuzz-$t.full" 2>&1
    rc=$?
    grep -E '^#[0-9]+|INFO: (fork|-fork|Seed|Loaded)|ERROR|SUMMARY|Deadly|crash' "$logs/fuzz-$t.full" | tail -200 >"$logs/fuzz-$t.log"
    echo "fuzz $t exit $rc: $(grep -E '^#[0-9]+' "$logs/fuzz-$t.full" | tail -1)"
  done
  tar -C "$logs" -cf "$OUT/fuzz-logs.tar" $(cd "$logs" && ls *.log)
  wait $soak
  echo "soak exit $?"
  tail -26 "$OUT/soak.log"
fi
if [[ $step == all || $step == bench ]]; then
  s=.carry/snell
  assets=(.assets/gltf/TransmissionRoughnessTest/glTF-Binary/*.glb .assets/gltf/GlassVaseFlowers/glTF-Binary/*.glb
          .assets/gltf/IridescenceSuzanne/glTF-Binary/*.glb .assets/gltf/TransmissionTest/glTF-Binary/*.glb)
  # At most eight files come back from the lent machine: the JSON goes in one tar.
  json=$(mktemp -d)
  {
    $s bench scale --json "$json/scale.json"
    echo "== H-PLOC with four teams a workgroup (128), against the default of one, same run"
    $s bench scale --crowds 0 --triangles 1000000,10000000 --hploc-workgroup 128 --json "$json/scale-hploc128.json"
    $s bench frame --crowd 2 --viewport --json "$json/frame-crowd2.json"
    $s bench frame --crowd 100 --viewport --size 3840x2160 --json "$json/frame-crowd100-4k.json"
    $s bench frame --eye-resolution 256 --viewport --json "$json/frame-eye256.json"
    $s bench frame --eye-resolution 256 --json "$json/frame-eye256-trace.json"
    $s bench frame --viewport --size 640x360 --json "$json/frame-eye-640x360.json"
    $s bench bvh --eye-resolution 256 "${assets[@]}" --json "$json/bvh.json"
  } 2>&1 | tee "$OUT/bench.log"
  tar -C "$json" -cf "$OUT/results.tar" .
fi
if [[ $step == all || $step == maps ]]; then
  .carry/snell bench methods --size 1920x1080 --frames 24 --methods trace,masked,iris-plane,normal-offset,refraction-map,none \
    --json "$OUT/maps.json" --svg "$OUT/maps.svg" 2>&1 | tee "$OUT/maps.log"
  .carry/snell bench frame --json "$OUT/frame.json" 2>&1 | tee -a "$OUT/maps.log"
fi
if [[ $step == all || $step == methods ]]; then
  s=.carry/snell
  json=$(mktemp -d)
  $s bench methods --size 1920x1080 --frames 24 --json "$json/methods.json" --svg "$OUT/methods.svg" 2>&1 |
    tee "$OUT/methods.log"
  {
    echo "== scaling, trace against driver-rt, same frames: image size (eye 64)"
    for size in 640x360 1920x1080 3840x2160; do
      $s bench methods --methods trace,driver-rt --no-reference --frames 8 --size $size --json "$json/scale-size-$size.json"
    done
    echo "== triangles (eye resolution 64 to 2048), 1920x1080"
    for r in 64 256 1024 2048; do
      $s bench methods --methods trace,driver-rt --no-reference --frames 8 --eye-resolution $r --json "$json/scale-eye-$r.json" \
        --size 1920x1080
    done
    echo "== characters, 3840x2160"
    for c in 1 10 100; do
      $s bench methods --methods trace,driver-rt --no-reference --frames 8 --crowd $c --size 3840x2160 \
        --json "$json/scale-crowd-$c.json"
    done
  } 2>&1 | grep -v "CPU reference" | tee "$OUT/methods-scaling.log"
  tar -C "$json" -cf "$OUT/methods-results.tar" .
fi
if [[ $step == all || $step == optics ]]; then
  s=.carry/snell
  json=$(mktemp -d)
  {
    echo "== optics features, time at 1920x1080 (no reference)"
    $s bench methods --optics --size 1920x1080 --frames 12 --no-reference --json "$json/optics-1080.json"
    echo "== optics features, error against the reference at 320x240"
    $s bench methods --optics --size 320x240 --frames 12 --json "$json/optics-320.json"
    echo "== stability grid, optics group, validation on"
    SNELL_VALIDATION=1 $s bench stress --only optics --json "$json/stress-optics.json"
  } 2>&1 | grep -v "CPU reference" | tee "$OUT/optics.log"
  tar -C "$json" -cf "$OUT/optics-results.tar" .
fi
if [[ $step == all || $step == textures ]]; then
  for m in .assets/gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf .assets/gltf/GlassVaseFlowers/glTF-Binary/*.glb; do
    for run in 1 2 3; do .carry/snell info "$m" --timings | grep -E "texture memory|load times"; done
  done 2>&1 | tee "$OUT/textures.log"
fi
if [[ $step == python ]]; then
  {
    python3 --version
    # pip's pybind11 and the machine's own CPython: the module is rebuilt there from python/.
    cmake -S python -B /tmp/pybuild -G Ninja -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE="$(command -v python3)" \
      -Dsnell_DIR="$PWD/.carry/prefix/lib/cmake/snell" -Dpybind11_DIR="$(python3 -m pybind11 --cmakedir)" >/tmp/pybuild.log 2>&1 &&
      cmake --build /tmp/pybuild >>/tmp/pybuild.log 2>&1 || { echo "the module did not build:"; tail -30 /tmp/pybuild.log; }
    echo "== the module replaying the Blender add-on's feed, 1920x1080 viewport composite"
    PYTHONPATH=/tmp/pybuild/python PYTHONUNBUFFERED=1 python3 bench/python_frame.py .carry/feed --frames 48 \
      --json "$OUT/python-frame.json"
    echo "== snell bench frame of Blender's glTF export of the same rig, same size"
    .carry/snell bench frame .carry/feed/rig.glb --viewport --size 1920x1080 --warmup 200 --frames 48 --json "$OUT/frame-rig.json"
  } 2>&1 | tee "$OUT/python.log"
fi
if [[ $step == usd ]]; then
  {
    python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl
    # The machine has the Vulkan loader (.gl) but not its headers: Debian's, carried in the install's include/.
    cmake -S python -B /tmp/pybuild -G Ninja -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE="$(command -v python3)" \
      -DVulkan_INCLUDE_DIR="$PWD/.carry/prefix/include" -DVulkan_LIBRARY=/usr/lib/x86_64-linux-gnu/libvulkan.so.1 \
      -Dsnell_DIR="$PWD/.carry/prefix/lib/cmake/snell" -Dpybind11_DIR="$(python3 -m pybind11 --cmakedir)" >/tmp/pybuild.log 2>&1 &&
      cmake --build /tmp/pybuild >>/tmp/pybuild.log 2>&1 || { echo "the module did not build:"; tail -30 /tmp/pybuild.log; }
    export PYTHONPATH=/tmp/pybuild/python:/tmp/site PYTHONUNBUFFERED=1
    for stage in usd-eyes usd-dense; do
      echo "== snell.usd's feed of .carry/$stage, 1920x1080, the trace"
      python3 bench/usd_feed.py --stage ".carry/$stage/eyes.usda" --no-textures --size 1920x1080 --frames 48 \
        --json "$OUT/usd-feed-$stage.json"
      echo "== the same, the viewport composite"
      python3 bench/usd_feed.py --stage ".carry/$stage/eyes.usda" --no-textures --size 1920x1080 --frames 48 --viewport \
        --json "$OUT/usd-feed-$stage-viewport.json"
      echo "== snell bench frame of its glTF twin, same size"
      [[ -n ${SKIP_FRAME:-} ]] || $snell bench frame ".carry/$stage/eyes.gltf" --size 1920x1080 --frames 48 \
        --json "$OUT/frame-$stage.json"
      [[ -n ${SKIP_FRAME:-} ]] || $snell bench frame ".carry/$stage/eyes.gltf" --viewport --size 1920x1080 --frames 48 \
        --json "$OUT/frame-$stage-viewport.json"
    done
  } 2>&1 | tee "$OUT/usd.log"
fi
if [[ $step == farm ]]; then
  echo "== GPUs as a launcher names them: CUDA_VISIBLE_DEVICES by index and by UUID, and one past the end"
  nvidia-smi -L | tee "$OUT/nvidia-smi-L.txt"
  nvidia-smi --query-gpu=index,pci.bus_id,uuid --format=csv | tee -a "$OUT/nvidia-smi-L.txt"
  .carry/snell info --devices | tee "$OUT/info-devices.txt"
  uuid=$(nvidia-smi --query-gpu=uuid --format=csv,noheader | head -1)
  n=0
  for v in 0 "$uuid" 1; do
    n=$((n + 1))
    CUDA_VISIBLE_DEVICES=$v SNELL_VALIDATION=1 .carry/snell render --eye --size 320x240 --frames 1-3 --method trace \
      -o "/tmp/farm$n.#.png" --stats-json "$OUT/cuda$n.#.json" > "$OUT/cuda$n.log" 2>&1
    echo "CUDA_VISIBLE_DEVICES=$v: exit $?"; grep -E "^device|error" "$OUT/cuda$n.log"
  done
  cmp <(grep image_hash "$OUT/cuda1.2.json") <(grep image_hash "$OUT/cuda2.2.json") && echo "index and UUID give the same pixels"
  SNELL_VALIDATION=1 .carry/snell_tests --gtest_brief=1 \
    --gtest_filter='FrameList.*:FramePattern.*:FarmPlan.*:FarmFolder.*:DeviceSelection.*:LauncherOverride.*:DeviceSurvey.*:Robustness.Sigterm*:Robustness.DeviceLost*' \
    > "$OUT/farm-tests.log" 2>&1
  echo "farm tests exit $?"; grep -E "FAILED|PASSED|tests ran" "$OUT/farm-tests.log" | tail -12
fi
if [[ $step == shot ]]; then
  echo "== every GPU of the host: bench shot, crowd 100 at 3840x2160, ${SHOT_FRAMES:-240} frames as PNG on the local disk"
  nvidia-smi --query-gpu=index,name,pci.bus_id,uuid --format=csv
  .carry/snell info --devices | tee "$OUT/info-devices.txt"
  df -h /tmp | tail -1; nproc
  SNELL_PIPELINE_CACHE=/tmp/snell-cache .carry/snell bench shot --frames "${SHOT_FRAMES:-240}" --folder /tmp/shot \
    --json "$OUT/shot.json" 2> "$OUT/shot-progress.log" | tee "$OUT/shot.txt"
  echo "bench shot exit ${PIPESTATUS[0]}"
  echo "== CUDA_VISIBLE_DEVICES=1 maps to the second GPU in PCI bus order; =0,1 with --devices all takes both"
  CUDA_VISIBLE_DEVICES=1 .carry/snell render --eye --size 320x240 --frames 1-2 -o /tmp/c1.#.png 2>&1 | grep -E "^device|error"
  CUDA_VISIBLE_DEVICES=0,1 .carry/snell render --eye --size 320x240 --frames 1-8 --devices all -o /tmp/c2.#.png 2>&1 | grep -E "device|frames on"
  SNELL_VALIDATION=1 .carry/snell_tests --gtest_brief=1 --gtest_filter='MultiDevice.*:DeviceList.*:LauncherOverride.*' \
    > "$OUT/multi-tests.log" 2>&1
  echo "multi-device tests exit $?"; grep -E "FAILED|PASSED|tests ran" "$OUT/multi-tests.log" | tail -8
fi
if [[ $step == shot1 ]]; then
  echo "== two workers on one GPU: bench shot --devices 0,0, crowd 100 at 3840x2160, ${SHOT_FRAMES:-24} frames as PNG"
  SNELL_PIPELINE_CACHE=/tmp/snell-cache $snell bench shot --devices 0,0 --frames "${SHOT_FRAMES:-24}" \
    --folder /tmp/shot --json "$OUT/shot1.json" 2> "$OUT/shot1-progress.log" | tee "$OUT/shot1.txt"
  echo "bench shot exit ${PIPESTATUS[0]}"
  CUDA_VISIBLE_DEVICES=0 $snell render --eye --size 320x240 --frames 1-8 --devices all -o /tmp/c2.#.png 2>&1 | grep -E "device|frames on"
  SNELL_VALIDATION=1 .carry/snell_tests --gtest_brief=1 --gtest_filter='MultiDevice.*:DeviceList.*:LauncherOverride.*' \
    > "$OUT/multi-tests.log" 2>&1
  echo "multi-device tests exit $?"; grep -E "FAILED|PASSED|tests ran" "$OUT/multi-tests.log" | tail -8
fi
if [[ $step == first ]]; then
  {
    TIMEFORMAT="%R s wall"
    for run in cold warm; do
      # Fresh caches for the cold run: the driver's own (NVIDIA reads __GL_SHADER_DISK_CACHE_PATH) and snell's.
      [[ $run == cold ]] && rm -rf /tmp/caches
      mkdir -p /tmp/caches/xdg /tmp/caches/nv
      echo "== $run: snell render --eye --size 1920x1080"
      time XDG_CACHE_HOME=/tmp/caches/xdg __GL_SHADER_DISK_CACHE_PATH=/tmp/caches/nv \
        $snell -q render --eye --size 1920x1080 -o /tmp/first.png
    done
    echo "== where a cold first frame goes (snell info --timings, empty caches)"
    $snell eye -o /tmp/eye.glb >/dev/null
    rm -rf /tmp/caches && mkdir -p /tmp/caches/xdg /tmp/caches/nv
    XDG_CACHE_HOME=/tmp/caches/xdg __GL_SHADER_DISK_CACHE_PATH=/tmp/caches/nv $snell info /tmp/eye.glb --timings | tail -2
    XDG_CACHE_HOME=/tmp/caches/xdg __GL_SHADER_DISK_CACHE_PATH=/tmp/caches/nv $snell info /tmp/eye.glb --timings | tail -1
  } 2>&1 | tee "$OUT/first.log"
fi
if [[ $step == trace ]]; then
  json=$(mktemp -d)
  {
    python3 bench/make_sphere.py 100000 /tmp/sphere-100k.gltf
    python3 bench/make_sphere.py 1000000 /tmp/sphere-1m.gltf
    for scene in /tmp/sphere-100k.gltf /tmp/sphere-1m.gltf eye; do
      name=$(basename "$scene" .gltf)
      [[ $scene == eye ]] && scene=""
      echo "== trace against driver-rt, 1920x1080, $name"
      $snell bench methods $scene --methods trace,driver-rt --no-reference --frames 8 --size 1920x1080 \
        --json "$json/trace-$name.json" | grep -v "CPU reference"
    done
  } 2>&1 | tee "$OUT/trace.log"
  tar -C "$json" -cf "$OUT/trace-results.tar" .
fi
if [[ $step == viewport ]]; then
  json=$(mktemp -d)
  {
    s=$snell
    $s bench frame --crowd 2 --viewport --warmup 200 --json "$json/frame-crowd2.json"
    $s bench frame --viewport --warmup 200 --json "$json/frame-eye64.json"
    $s bench frame --eye-resolution 256 --viewport --warmup 200 --json "$json/frame-eye256.json"
    $s bench frame --crowd 100 --viewport --size 3840x2160 --warmup 100 --json "$json/frame-crowd100-4k.json"
    $s bench frame --viewport --orbit --warmup 200 --json "$json/frame-eye64-orbit.json"
  } 2>&1 | grep -E "scene:|^refraction|^frame |^wall|device:" | tee "$OUT/viewport.log"
  tar -C "$json" -cf "$OUT/viewport-results.tar" .
fi
if [[ $step == build ]]; then
  $snell bench scale --crowds 0 --triangles 1000000,10000000 --json "$OUT/scale.json" 2>&1 | tee "$OUT/scale.log"
fi
