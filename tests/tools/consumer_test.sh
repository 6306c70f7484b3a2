#!/bin/bash
# Installs snell from a build tree into a fresh prefix, builds examples/consumer
# against that prefix alone with find_package(snell), and renders a frame with it.
# usage: consumer_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 source=$2
work=$(mktemp -d /tmp/snell-consumer.XXXXXX)
trap 'rm -rf "$work"' EXIT

cmake --install "$build" --prefix "$work/prefix" >/dev/null
for f in include/snell/snell.h lib/cmake/snell/snellConfig.cmake lib/cmake/snell/snellConfigVersion.cmake bin/snell; do
  [ -e "$work/prefix/$f" ] || { echo "not installed: $f"; exit 1; }
done
lib=$(ls "$work"/prefix/lib*/libsnell.so* 2>/dev/null | head -1 || true)
[ -n "$lib" ] || lib=$(ls "$work"/prefix/lib/*/libsnell.so* | head -1)
# The layers inside the library stay hidden: a host sees snell:: and nothing deeper.
inner=$(nm -DC --defined-only "$lib" | grep -cE 'snell::(vk|render|scene|bake|peer)::' || true)
[ "$inner" = 0 ] || { echo "libsnell exports $inner internal symbols"; exit 1; }

cmake -S "$source/examples/consumer" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/build" >/dev/null
"$work/prefix/bin/snell" eye -o "$work/eye.glb" >/dev/null
"$work/build/consumer" "$work/eye.glb" "$work/eye.ppm" 64 48
head -c 15 "$work/eye.ppm" | grep -q "^P6" || { echo "no PPM written"; exit 1; }
size=$(stat -c %s "$work/eye.ppm")
[ "$size" = $((13 + 64 * 48 * 3)) ] || { echo "PPM of $size bytes"; exit 1; }
# The Python module, where the build made one: installed into the prefix's dist-packages, finding libsnell there.
if [ -d "$build/python/snell" ]; then
  site=$(ls -d "$work"/prefix/lib/python3*/dist-packages 2>/dev/null | head -1)
  [ -n "$site" ] || { echo "the Python module was not installed"; exit 1; }
  PYTHONPATH="$site" /usr/bin/python3 -c "import snell; assert snell.version()" ||
    { echo "the installed Python module does not import"; exit 1; }
fi
echo "consumer built against $work/prefix and rendered a frame"
