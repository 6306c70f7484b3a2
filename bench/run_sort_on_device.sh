#!/usr/bin/env bash
# Runs on the lent NVIDIA machine (see ../.library/device): the test suite with
# validation, a tuning sweep, then `snell bench sort` and the CUB peer in one
# run, joined into one table. Binaries are built on the Debian machine and
# carried in .carry/ (snell, snell_tests, the validation layer); the Vulkan
# loader in .gl/. Results land in $OUT.
set -uo pipefail
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[[ -f $icd ]] && export VK_DRIVER_FILES=$icd
export VK_ADD_LAYER_PATH=$PWD/.carry/layer LD_LIBRARY_PATH=$PWD/.carry/lib:$PWD/.carry
OUT=${OUT:-/tmp/out}
mkdir -p "$OUT"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.mem --format=csv | tee "$OUT/gpu.txt"
.carry/snell info --devices | tee -a "$OUT/gpu.txt"

step=${1:-all}
if [[ $step == all || $step == tests ]]; then
  echo "== tests on the GPU, validation on"
  .carry/snell_tests --gtest_brief=1 > "$OUT/tests.log" 2>&1
  echo "tests exit $?"; tail -5 "$OUT/tests.log"
fi
if [[ $step == all || $step == sweep ]]; then
  echo "== tuning sweep at 2^24: key bits, workgroup, keys per invocation"
  for shape in ${SWEEP:-"32 256 8" "32 256 12" "32 256 16" "64 256 8" "64 256 12"}; do
    set -- $shape
    printf -- "-- %s-bit keys, workgroup %s, %s keys each: " "$1" "$2" "$3"
    .carry/snell bench sort --keys "$1" --min-log 24 --max-log 24 --runs 10 --workgroup "$2" --keys-per-thread "$3" 2>&1 | tail -1
  done
fi
if [[ $step == all || $step == bench ]]; then
  echo "== building the CUB peer"
  nvcc -O3 -std=c++17 -arch=sm_90 bench/peers/cub_sort.cu -o /tmp/cub_sort || exit 1
  echo "== snell bench sort"
  .carry/snell bench sort ${SNELL_SORT_ARGS:-} --json "$OUT/sort-snell.json" || exit 1
  echo "== CUB"
  /tmp/cub_sort --json "$OUT/sort-cub.json" || exit 1
  python3 bench/sort_table.py "$OUT/sort-snell.json" "$OUT/sort-cub.json" "$OUT/sort.md" "$OUT/sort.json"
fi
