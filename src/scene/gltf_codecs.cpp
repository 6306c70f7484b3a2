// tinygltf's and stb's implementations, compiled from Debian's headers (libtinygltf-dev, libstb-dev) into a
// self-contained libsnell.so (SNELL_SELF_CONTAINED, for the Blender extension's wheels) in place of Debian's
// libtinygltf.so and libstb.so; the top CMakeLists.txt says why.
#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <tiny_gltf.h>
