// The viewer's display pass (shaders/viewer/present.comp): one viewport's
// composite (linear rgba16f) into the window's 8-bit image, encoded as sRGB,
// or the BVH cost heat map from the trace's per-pixel node visits, with the
// film gate drawn over it.
#ifndef SNELL_PRESENT_H
#define SNELL_PRESENT_H
#include "shared_types.h"

SNELL_GPU_BEGIN

SNELL_CONST kPresentFlagHeatMap = 1u;  // colour by TraceAov::nodeVisits instead of the composite
SNELL_CONST kPresentFlagGate = 2u;     // dim outside the film gate and outline it
SNELL_CONST kPresentFlagActive = 4u;   // outline the viewport (the one the mouse drives)

SNELL_CONST kPresentBindingComposite = 0;  // rgba16f storage image
SNELL_CONST kPresentBindingAov = 1;        // TraceAov[width * height]
SNELL_CONST kPresentBindingOutput = 2;     // rgba8 storage image: the whole window

// 48 bytes, total: 48 bytes
struct PresentPush {
  uvec4 area;     // 16: x, y of the viewport in the output, its width and height
  vec4 gate;      // 16: the film gate in viewport pixels: x0, y0, x1, y1
  uint flags;     // 4: kPresentFlag*
  float heatMax;  // 4: node visits shown as the hottest colour
  uint pad0;      // 4
  uint pad1;      // 4
};

SNELL_GPU_END
#endif
