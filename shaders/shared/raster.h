// The raster pass (shaders/raster/): draws every draw item from the same
// deformed vertex buffers the trace uses (vertex pulling), Phong-shades opaque
// fragments as trace.h states, and gives each transmissive fragment the trace
// image's texel at its own pixel. A depth-only pre-pass comes first, so the
// shading pass runs once per pixel (depth test EQUAL). Coverage is sampled at pixel centres, the
// points the trace's primary rays go through, so the two agree pixel for pixel
// away from silhouettes. Depth is reverse Z (near is 1, infinity is 0).
#ifndef SNELL_RASTER_H
#define SNELL_RASTER_H
#include "shared_types.h"

SNELL_GPU_BEGIN

SNELL_CONST kRasterFlagOrthographic = 1u;
SNELL_CONST kRasterFlagWireframe = 4u;     // the wireframe overlay: one flat colour

// Binding slots of set 0 (the same buffers the trace binds).
SNELL_CONST kRasterBindingInstances = 0;  // GpuInstance[]
SNELL_CONST kRasterBindingPositions = 1;  // float[3 * vertexCount]
SNELL_CONST kRasterBindingNormals = 2;    // float[3 * vertexCount]
SNELL_CONST kRasterBindingTexcoords = 3;  // vec4[vertexCount]
SNELL_CONST kRasterBindingIndices = 4;    // uint[3 * triangleCount], absolute
SNELL_CONST kRasterBindingMaterials = 5;  // GpuMaterial[]
SNELL_CONST kRasterBindingTextures = 6;   // GpuTexture[]
SNELL_CONST kRasterBindingTexels = 7;     // uint[]: RGBA8
SNELL_CONST kRasterBindingLights = 8;     // GpuLight[]
SNELL_CONST kRasterBindingTraceImage = 9; // rgba16f storage image, read at the fragment's pixel

// One draw per draw item: gl_InstanceIndex is the item, gl_VertexIndex / 3
// the absolute triangle. Vectors are relative to the frame's origin.
// 96 bytes, total: 96 bytes
struct RasterPush {
  vec4 right;      // 16: xyz; w: 1 / half width of the view (at unit distance, or of the ortho view)
  vec4 up;         // 16: xyz; w: 1 / half height
  vec4 forward;    // 16: xyz; w: near plane distance (perspective) or nearest depth (orthographic)
  vec4 eye;        // 16: xyz; w: farthest depth (orthographic)
  vec4 wireColor;  // 16: rgba of the wireframe overlay
  uint flags;      // 4: kRasterFlag*
  uint lightCount; // 4: 0: the headlight
  float shiftX;    // 4: the film back's offset (View::shift)
  float shiftY;    // 4
};

SNELL_GPU_END
#endif
