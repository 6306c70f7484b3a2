// Helpers every BVH pass shares: boxes as six floats, surface areas, float
// keys whose unsigned order is the float order (so atomicMin can reduce
// floats); bvh_entry_of.glsl maps a thread to the build or refit entry it
// serves (included after the entries buffer it reads).
#include "../../shared/bvh.h"

layout(local_size_x_id = kBvhSpecWorkgroupSize) in;
#include "../../common/dispatch.glsl"
layout(push_constant) uniform Push { BvhPush pc; };

const float kInf = 1.0 / 0.0;  // folded to +infinity at compile time


uint orderedKey(float f) {
  uint u = floatBitsToUint(f);
  return (u & 0x80000000u) != 0u ? ~u : (u | 0x80000000u);
}

float orderedFloat(uint k) {
  return uintBitsToFloat((k & 0x80000000u) != 0u ? (k & 0x7fffffffu) : ~k);
}

bool finite3(vec3 v) {
  return !any(isnan(v)) && !any(isinf(v));
}

// An empty box: no ray enters it and it grows no union.
void emptyBox(out vec3 lo, out vec3 hi) {
  lo = vec3(kInf);
  hi = vec3(-kInf);
}

float boxArea(vec3 lo, vec3 hi) {
  vec3 d = max(hi - lo, vec3(0.0));
  return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

// A fixed-point SAH term (kBvhSahScale units of the build's root area).
uint sahTerm(float area, float unitScale) {
  return uint(min(area * unitScale + 0.5, float(kBvhSahTermCap)));
}
