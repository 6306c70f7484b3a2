#!/bin/bash
# Builds the Debian package from a build tree with CPack (as scripts/package
# does from the release build), checks what it holds and what it depends on,
# asks apt whether a Debian 12 machine could install it, then unpacks it with
# dpkg-deb -x into a temporary root and renders from there: with the command,
# and with the Python module finding libsnell.so beside it.
# usage: package_test.sh BUILD_DIR
set -euo pipefail
build=$1
work=$(mktemp -d /tmp/snell-package.XXXXXX)
trap 'rm -rf "$work"' EXIT
fail() { echo "package test: $*" >&2; exit 1; }

cpack --config "$build/CPackConfig.cmake" -B "$work/out" >"$work/cpack.log" 2>&1 || { cat "$work/cpack.log"; fail "cpack failed"; }
deb=$(ls "$work"/out/snell_*_*.deb 2>/dev/null | head -1)
[ -n "$deb" ] || fail "cpack wrote no snell_VERSION_ARCH.deb"
echo "built $(basename "$deb"), $(stat -c %s "$deb") bytes"

# What it holds: the command, the library with headers and CMake package, the module, the add-on, the licences.
dpkg-deb -c "$deb" | awk '{print $6}' >"$work/contents"
for f in ./usr/bin/snell ./usr/include/snell/snell.h ./usr/lib/cmake/snell/snellConfig.cmake \
         ./usr/lib/python3/dist-packages/snell/__init__.py ./usr/share/blender/scripts/addons/snell_blender/__init__.py \
         ./usr/share/blender/scripts/addons/snell_blender/LICENSE ./usr/share/doc/snell/LICENSE ./usr/share/doc/snell/NOTICE; do
  grep -qxF "$f" "$work/contents" || fail "the package lacks $f"
done
grep -qE '^\./usr/lib/(.*/)?libsnell\.so\.[0-9]' "$work/contents" || fail "the package lacks libsnell.so"
grep -qE '^\./usr/lib/(.*/)?snell/libsnell_exr\.so$' "$work/contents" || fail "the package lacks the EXR module"
grep -qE '^\./usr/lib/python3/dist-packages/snell/_snell\..*\.so$' "$work/contents" || fail "the package lacks the module's extension"
if grep -q "__pycache__\|/tests/\|snell_tests" "$work/contents"; then fail "the package holds build or test files"; fi

# What it depends on: the libraries its binaries link (dpkg-shlibdeps), a Vulkan driver, Python and numpy.
depends=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $depends"
for p in libvulkan1 libc6 libstdc++6 libtinygltf2d mesa-vulkan-drivers python3 python3-numpy; do
  [[ ", $depends," == *", $p "* || ", $depends," == *", $p,"* ]] || fail "Depends lacks $p"
done
# apt resolves every dependency from Debian's archive (a simulation: nothing is installed).
apt-get install -s "$deb" >"$work/apt.log" 2>&1 || { cat "$work/apt.log"; fail "apt cannot install it"; }
grep -q "^Inst snell " "$work/apt.log" || { cat "$work/apt.log"; fail "apt would not install snell"; }

# Unpacked into a temporary root, it renders.
dpkg-deb -x "$deb" "$work/root"
"$work/root/usr/bin/snell" eye -o "$work/eye.glb" >/dev/null
"$work/root/usr/bin/snell" render "$work/eye.glb" -o "$work/eye.png" --size 64x48 -q
[ "$(head -c 8 "$work/eye.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || fail "the unpacked command wrote no PNG"
# EXR through the package's own OpenImageIO module (usr/lib/snell), found beside the command, not the build's.
LD_DEBUG=files "$work/root/usr/bin/snell" render "$work/eye.glb" -o "$work/eye.exr" --size 64x48 -q 2>"$work/ld.log"
[ "$(head -c 4 "$work/eye.exr" | od -An -tx1 | tr -d ' \n')" = 762f3101 ] || fail "the unpacked command wrote no EXR"
grep -q "file=$work/root/usr/lib/.*snell/libsnell_exr.so" "$work/ld.log" || fail "the EXR module did not come from the package"
PYTHONPATH="$work/root/usr/lib/python3/dist-packages" /usr/bin/python3 - "$work/eye.glb" <<'PY' || fail "the unpacked module does not render"
import sys
import snell
with snell.Device() as device, snell.Scene.load(sys.argv[1]) as scene:
    image = snell.Renderer(device, scene).render(snell.View(48, 32, camera=0))
assert image.shape == (32, 48, 4), image.shape
assert image[..., :3].max() > 0.05, "a black picture"
loaded = [line.split()[-1] for line in open("/proc/self/maps") if "libsnell.so" in line]
assert loaded and all("/root/usr/lib/" in path for path in loaded), f"libsnell.so came from {loaded}"
print("the unpacked module rendered", image.shape, "from", snell.__file__)
PY
echo "the package holds what it should and renders from its own files"
