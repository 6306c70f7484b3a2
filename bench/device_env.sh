# Sourced by bench/run_frame_on_device.sh and bench/run_builds_on_device.sh on
# the lent NVIDIA machine (see ../.library/device): unpacks the carried Vulkan
# loader (.gl), points it at NVIDIA's driver and snell at the carried libraries
# and validation layer (.carry), the goldens and the carried assets (.assets:
# the asset-driven tests instantiate over what is there); results go to $OUT.
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[[ -f $icd ]] && export VK_DRIVER_FILES=$icd
export LD_LIBRARY_PATH=$PWD/.carry/lib:$PWD/.carry VK_ADD_LAYER_PATH=$PWD/.carry/layer XDG_RUNTIME_DIR=/tmp
export SNELL_ASSETS_DIR=$PWD/.assets SNELL_GOLDEN_DIR=$PWD/golden
mkdir -p "$SNELL_ASSETS_DIR/gltf" "$SNELL_ASSETS_DIR/gltf-invalid"
export OUT=${OUT:-/tmp/out}
mkdir -p "$OUT"
