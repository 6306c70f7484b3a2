#!/usr/bin/env bash
# The standing A/B: builds of snell timed side by side in one lease of the GPU
# machine, so a change is measured against the last landed main and never
# against a base that already has the change's cost in it.
#
# On the Debian machine:
#   bench/compare.sh build [NAME=]REV[+PATCH...] ...
#                                           each revision's `snell` (device preset: no OpenImageIO), with
#                                           the patches named applied (an experiment of bench/experiments), built in
#                                           build/compare/NAME, stripped into .carry/snell-NAME, with the
#                                           Debian libraries the GPU machine lacks in .carry/lib, the
#                                           validation layer in .carry/layer and the Vulkan loader's
#                                           packages in .gl (NAME defaults to the revision as given)
# On the GPU machine (the device tool: `bench/compare.sh run`, carrying .carry and .gl):
#   bench/compare.sh run [ROUNDS]           every carried build in turn, ROUNDS rounds (default 3), the
#                                           order reversed every other round; then one table
#   bench/compare.sh REV_A REV_B            build both here; then says what to run there
#
# Rows: trace against driver-rt (`bench methods --methods trace,driver-rt`, 1920x1080, 8 frames, Fresnel on)
# on the glass spheres of 100k and 1M triangles (bench/make_sphere.py) and the procedural eye; then the
# viewport's refraction work (`bench frame --viewport`): two characters, the eye at 64 and 256, a crowd
# of 100 at 4K. The table gives each build's median over the rounds, the spread (min-max) and the
# ratio of the first build's time to each other's, and whether each build draws the three trace
# scenes with the same pixels (`snell render --stats-json`'s image hash, first round);
# $OUT/compare.json holds every measurement (ROWS=registers adds the driver's register and spill counts
# of each build's trace pipelines, $OUT/registers.log). ROWS=pipelines compiles each build's trace
# specialisations (`snell bench pipelines --trace-spirv`, with the newest carried snell that has the
# command) on the GPU's driver and, on AMD's compiler through RADV's null device (gfx1100), here at
# `build` (the GPU machine has no RADV), and puts both side by side in $OUT/pipelines.md. BUILDS
# (names, space-separated) limits `run` to some of the carried builds, and NAME+VAR=VALUE runs build
# NAME with VAR=VALUE set (an experiment's switch); ROWS limits it to some rows (same, trace, viewport,
# registers, pipelines, plain). ROWS=plain times the trace on both spheres with a grey floor
# (make_sphere.py --plain): the pipeline without texture sampling, whose registers are the walk's.
set -uo pipefail
cd "$(dirname "$0")/.."

usage() { awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; }

# The Vulkan loader and what a device build links that the GPU machine's image lacks.
carry_runtime() {
  mkdir -p .carry/lib .carry/layer .gl
  local exclude
  exclude="$(git rev-parse --git-common-dir)/info/exclude"
  for ignored in /.carry/ /.gl/; do grep -qx "$ignored" "$exclude" 2>/dev/null || echo "$ignored" >>"$exclude"; done
  if ! ls .gl/libvulkan1_*.deb >/dev/null 2>&1; then
    local o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
    mkdir -p /tmp/amd64/partial
    apt-get $o update -qq && (cd .gl && apt-get $o download -qq libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
  fi
  cp -u /usr/lib/x86_64-linux-gnu/libVkLayer_khronos_validation.so .carry/layer/
  # The manifest names the library bare, which the loader looks up on the library path, not beside it.
  sed 's|"library_path": "libVkLayer|"library_path": "./libVkLayer|' \
    /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json >.carry/layer/VkLayer_khronos_validation.json
}

build_one() {
  local spec=$1 name rev patches=()
  name=${spec%%=*} rev=${spec#*=}
  [[ $spec == *=* ]] || name=$rev
  if [[ $rev == *+* ]]; then
    IFS=+ read -r -a patches <<<"${rev#*+}"
    rev=${rev%%+*}
  fi
  local src=build/compare/$name
  # Resolved here: inside the build's worktree, HEAD (or a relative name) would mean that worktree's own.
  rev=$(git rev-parse --verify -q "$rev^{commit}") || { echo "compare: no revision '${spec#*=}'" >&2; return 2; }
  if [[ -d $src ]]; then
    git -C "$src" reset -q --hard && git -C "$src" checkout -q --detach "$rev"
  else
    git worktree add -q --detach "$src" "$rev"
  fi
  local patch
  for patch in "${patches[@]}"; do
    git -C "$src" apply "$PWD/$patch" || { echo "compare: $patch does not apply on $rev" >&2; return 2; }
  done
  local what
  what="$(git log -1 --format='%h %s' "$rev" | cut -c1-80)${patches[*]:+ + ${patches[*]}}"
  echo "== $name: $what"
  (cd "$src" && cmake --preset device -DSNELL_BUILD_TESTS=OFF -DCMAKE_CXX_COMPILER_LAUNCHER=ccache >/dev/null &&
     cmake --build --preset device -j "$(nproc)" --target snell >/dev/null) || { echo "compare: $name did not build" >&2; return 1; }
  strip -o ".carry/snell-$name" "$src/build/device/snell"
  echo "$what" >".carry/snell-$name.rev"  # `run` names what each build is
  # Its trace as SPIR-V, for ROWS=pipelines.
  glslangValidator --quiet --target-env vulkan1.3 -g0 -o ".carry/trace-$name.spv" "$src/shaders/comp/trace.comp"
  # Libraries of Debian's that the GPU machine's image does not have.
  ldd "$src/build/device/snell" | awk '/=> \// {print $3}' | while read -r lib; do
    case $(basename "$lib") in
      libc.so*|libm.so*|libstdc++*|libgcc_s*|libvulkan*|ld-linux*|libpthread*|libdl*|librt*) ;;
      *) cp -u "$lib" .carry/lib/ ;;
    esac
  done
}

# The newest carried snell that has `bench pipelines` (it compiles any build's trace: --trace-spirv).
pipelines_tool() {
  local f
  for f in $(ls -t .carry/snell-* 2>/dev/null | grep -v '\.rev$'); do
    "$f" bench pipelines --help >/dev/null 2>&1 && { echo "$f"; return 0; }
  done
  return 1
}

# Runs build NAME, or NAME+VAR=VALUE: that build with VAR=VALUE in its environment (an experiment's switch).
snell_of() {
  local b=$1
  shift
  if [[ $b == *+*=* ]]; then
    env "${b#*+}" ".carry/snell-${b%%+*}" "$@"
  else
    ".carry/snell-$b" "$@"
  fi
}

run_all() {
  local rounds=${1:-3}
  source bench/device_env.sh
  nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null
  local builds=()
  if [[ -n ${BUILDS:-} ]]; then read -r -a builds <<<"$BUILDS"; else
    for f in .carry/snell-*; do [[ $f == *.rev ]] || builds+=("${f#.carry/snell-}"); done
  fi
  ((${#builds[@]})) || { echo "compare: no builds in .carry (bench/compare.sh build REV ...)" >&2; exit 2; }
  local rows=${ROWS:-same trace viewport} scenes=/tmp/compare-scenes log=$OUT/compare.log
  mkdir -p $scenes
  [[ -f $scenes/sphere-100k.gltf ]] || {
    python3 bench/make_sphere.py 100000 $scenes/sphere-100k.gltf
    python3 bench/make_sphere.py 1000000 $scenes/sphere-1m.gltf
    python3 bench/make_sphere.py --plain 100000 $scenes/sphere-100k-plain.gltf
    python3 bench/make_sphere.py --plain 1000000 $scenes/sphere-1m-plain.gltf
  } >/dev/null
  # Each build keeps its own warm pipeline caches: what is timed is the frames, not the compiles.
  export __GL_SHADER_DISK_CACHE_PATH=/tmp/compare-nv
  : >"$log"
  local b
  for b in "${builds[@]}"; do echo "build ${b}: $(cat ".carry/snell-${b%%+*}.rev" 2>/dev/null || echo '(revision not recorded)')"; done
  # A warm-up run, not counted: the first run of a lease met a GPU still raising its clocks (15-45% slower).
  snell_of "${builds[0]}" bench methods "$scenes/sphere-100k.gltf" --methods trace --no-reference --frames 8 \
    --size 1920x1080 >/dev/null 2>&1
  for ((round = 0; round < rounds; ++round)); do
    local order=("${builds[@]}")
    if ((round % 2)); then
      order=()
      for ((i = ${#builds[@]} - 1; i >= 0; --i)); do order+=("${builds[i]}"); done
    fi
    for b in "${order[@]}"; do
      export SNELL_PIPELINE_CACHE=/tmp/compare-cache-${b//[^A-Za-z0-9_.-]/_}
      mkdir -p "$SNELL_PIPELINE_CACHE"
      local traced=()
      [[ $rows == *trace* ]] && traced+=(sphere-100k sphere-1m eye)
      [[ $rows == *plain* ]] && traced+=(sphere-100k-plain sphere-1m-plain)
      if ((${#traced[@]})); then
        for s in "${traced[@]}"; do
          local args=()  # bench methods draws the procedural eye without a scene
          [[ $s != eye ]] && args=("$scenes/$s.gltf")
          echo "@@ round=$round build=$b row=$s"
          snell_of "$b" bench methods "${args[@]}" --methods trace,driver-rt --no-reference --frames 8 \
            --size 1920x1080 2>&1 | grep -E "rays per second"
        done
      fi
      if [[ $rows == *same* ]] && ((round == 0)); then
        for s in sphere-100k sphere-1m eye; do
          local args=(--eye)
          [[ $s != eye ]] && args=("$scenes/$s.gltf")
          snell_of "$b" -q render "${args[@]}" --method trace --size 1920x1080 -o "/tmp/compare-$s-$b.png" \
            --stats-json "/tmp/compare-$s-$b.json" >/dev/null 2>&1
          echo "@@ round=$round build=$b row=pixels-$s"
          echo "image hash $(grep -o '"image_hash": *"[^"]*"' "/tmp/compare-$s-$b.json" | cut -d'"' -f4)"
        done
      fi
      if [[ $rows == *registers* ]] && ((round == 0)); then  # the driver's statistics of each trace pipeline
        for s in sphere-100k eye; do
          local args=()
          [[ $s != eye ]] && args=("$scenes/$s.gltf")
          echo "== $b, $s"
          snell_of "$b" bench methods "${args[@]}" --methods trace,driver-rt --no-reference --frames 1 \
            --size 640x360 --pipeline-stats 2>&1 | grep -iE "register|spill|stack|trace \(" | sort -u
        done >>"$OUT/registers.log"
      fi
      if [[ $rows == *viewport* ]]; then
        local -A frame=([crowd-2]="--crowd 2" [eye-64]="" [eye-256]="--eye-resolution 256"
                        [crowd-100-4k]="--crowd 100 --size 3840x2160")
        for v in crowd-2 eye-64 eye-256 crowd-100-4k; do
          echo "@@ round=$round build=$b row=viewport-$v"
          # shellcheck disable=SC2086
          snell_of "$b" bench frame ${frame[$v]} --viewport --warmup 200 2>&1 | grep -E "^refraction "
        done
      fi
    done | tee -a "$log"
  done
  if [[ $rows == *pipelines* ]]; then  # registers and spills: the GPU's driver here, AMD's from `build`
    local tool
    tool=$(pipelines_tool) || { echo "compare: no carried snell has 'bench pipelines'" >&2; return 1; }
    for b in "${builds[@]}"; do
      "$tool" bench pipelines --only trace: --trace-spirv ".carry/trace-${b%%+*}.spv" \
        --json "$OUT/pipelines-${b%%+*}-gpu.json" >/dev/null 2>>"$OUT/pipelines.log"
      cp ".carry/pipelines-${b%%+*}-gfx1100.json" "$OUT/" 2>/dev/null
    done
    python3 bench/pipelines_table.py "$OUT" "${builds[@]%%+*}" | tee "$OUT/pipelines.md"
    [[ $rows == pipelines ]] && return 0
  fi
  python3 bench/compare_table.py "$log" --json "$OUT/compare.json" --order "${builds[*]}" | tee "$OUT/compare.md"
}

case ${1:-} in
  build)
    shift
    (($#)) || { usage >&2; exit 2; }
    carry_runtime
    for spec in "$@"; do build_one "$spec" || exit $?; done
    # AMD's statistics of each build's trace (ROWS=pipelines), which need no GPU: here, once all are built.
    if tool=$(pipelines_tool); then
      for spec in "$@"; do
        name=${spec%%=*}
        "$tool" bench pipelines --amd gfx1100 --only trace: --trace-spirv ".carry/trace-$name.spv" \
          --json ".carry/pipelines-$name-gfx1100.json" >/dev/null || echo "compare: no AMD statistics of $name" >&2
      done
    fi
    ls -la .carry/ .carry/lib
    ;;
  run) shift; run_all "$@" ;;
  -h|--help|help|'') usage ;;
  *)
    (($# == 2)) || { usage >&2; exit 2; }
    "$0" build "$1" "$2" || exit $?
    echo "now, on the GPU machine (device tool, carry .carry and .gl): BUILDS='$1 $2' bench/compare.sh run"
    ;;
esac
