// The raster pass (shaders/raster/): draws every draw item from the same
// deformed vertex buffers the trace uses (vertex pulling), Phong-shades opaque
// fragments as trace.h states, and gives each transmissive fragment the trace
// image's texel at its own pixel. A depth-only pre-pass comes first, so the
// shading pass runs once per pixel (depth test EQUAL). Coverage is sampled at pixel centres, the
// points the trace's primary rays go through, so the two agree pixel for pixel
// away from silhouettes. Depth is reverse Z (near is 1, infinity is 0).
#ifndef SNELL_RASTER_H
#define SNELL_RASTER_H
#include "scene.h"

SNELL_GPU_BEGIN

SNELL_CONST kRasterFlagOrthographic = 1u;
SNELL_CONST kRasterFlagWireframe = 4u;     // the wireframe overlay: one flat colour
// Screen-space refraction (no trace): a transmissive fragment reads the image
// of what lies behind the glass (drawn first, glass left out) at a displaced pixel.
SNELL_CONST kRasterFlagNormalOffset = 8u;  // displaced by the shading normal times offsetStrength (GPU Gems 2, ch. 19)
SNELL_CONST kRasterFlagIrisPlane = 16u;    // where the refracted ray meets the plane through what lies straight behind
// The pre-pass's uint attachment takes the view depth's float bits of the
// nearest face (0: nothing), for kRasterFlagIrisPlane, instead of the transmissive mask.
SNELL_CONST kRasterFlagBehindDepth = 32u;
// A baked refraction map (no trace): a transmissive fragment redraws the
// baked pixel at its place on the screen, shine + weight * the texture
// behind at the baked UV (RefractionTexel), however the scene moved since.
SNELL_CONST kRasterFlagRefractionMap = 64u;
// The trace drew this frame's see-through pixels (the mask's), so faces that
// alpha may make see-through read the trace image too; without it they are opaque.
SNELL_CONST kRasterFlagTraced = 128u;

// The raster pass's own binding slots, after the scene binding set (shared/scene.h).
SNELL_CONST kRasterBindingTraceImage = kSceneBindingCount + 0;   // rgba16f storage image, read at the fragment's pixel (or displaced)
SNELL_CONST kRasterBindingBehindDepth = kSceneBindingCount + 1;  // r32ui storage image: view depth bits behind the glass (kRasterFlagIrisPlane)
SNELL_CONST kRasterBindingRefractionMap = kSceneBindingCount + 2;  // RefractionTexel per baked pixel (kRasterFlagRefractionMap)

// One pixel of a baked refraction map as the raster pass reads it: what
// TraceAov split the traced colour into at the baked pose and view.
// 48 bytes, total: 48 bytes
struct RefractionTexel {
  vec4 shine;     // 16: rgb: added whatever the texture holds; w: 1 where the baked pixel showed glass, else 0
  vec4 weight;    // 16: rgb: what the texture's colour is multiplied by; w: the level of detail it is read at
  float u;        // 4: the UV in `material`'s base colour texture (transformed)
  float v;        // 4
  uint material;  // 4: whose base colour texture; kNoHit: none (the texture reads as 1)
  uint pad0;      // 4
};

// One draw per draw item: gl_InstanceIndex is the item, gl_VertexIndex / 3
// the absolute triangle. Vectors are relative to the frame's origin.
// 112 bytes, total: 112 bytes
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
  float offsetStrength;  // 4: kRasterFlagNormalOffset's displacement per unit of normal, in image heights
  uint mapWidth;   // 4: the refraction map's size in pixels (kRasterFlagRefractionMap)
  uint mapHeight;  // 4
  uint pad0;       // 4
};

SNELL_GPU_END
#endif
