// Reading and writing BvhNode's quantised child boxes (shared/bvh.h): the
// trace decodes them, builds and refits encode them. Decoding is
// origin + steps * step, where the product is exact (steps <= 255 and the step
// a power of two), so it rounds once and the same way on every device, fused
// or not; encoding checks each face against that very sum, so a decoded box
// always holds the exact box it came from.

const float kBvhInfinity = 1.0 / 0.0;

vec3 nodeStep(uint scale) {
  return vec3(uintBitsToFloat((scale & 0xffu) << 23), uintBitsToFloat(((scale >> 8) & 0xffu) << 23),
              uintBitsToFloat(((scale >> 16) & 0xffu) << 23));
}

uint nodeByte(uint quant[3], uint i) {
  return (quant[i >> 2] >> (8u * (i & 3u))) & 0xffu;
}

// Child c's box as the node stores it; an empty child comes back with lo > hi.
void decodeChild(BvhNode node, uint c, out vec3 lo, out vec3 hi) {
  uint b = 6u * c;
  uvec3 qlo = uvec3(nodeByte(node.quant, b), nodeByte(node.quant, b + 1u), nodeByte(node.quant, b + 2u));
  uvec3 qhi = uvec3(nodeByte(node.quant, b + 3u), nodeByte(node.quant, b + 4u), nodeByte(node.quant, b + 5u));
  vec3 origin = vec3(node.origin[0], node.origin[1], node.origin[2]);
  vec3 step = nodeStep(node.scale);
  lo = origin + vec3(qlo) * step;
  hi = origin + vec3(qhi) * step;
  if (qlo.x > qhi.x) {
    lo = vec3(kBvhInfinity);
    hi = vec3(-kBvhInfinity);
  }
}

// The smallest power-of-two step (a biased exponent, at least 1) for which
// origin + 255 steps reaches hi.
uint stepExponent(float origin, float hi) {
  uint bits = floatBitsToUint(max(hi - origin, 0.0) * (1.0 / 255.0));
  uint e = max((bits >> 23) + ((bits & 0x7fffffu) != 0u ? 1u : 0u), 1u);
  for (uint k = 0u; k < 16u && e < 254u && origin + 255.0 * uintBitsToFloat(e << 23) < hi; ++k) ++e;
  return min(e, 254u);
}

// Steps from origin to lo (rounded down) and to hi (rounded up), such that
// the decoded faces hold [lo, hi]. `inverse` is 1 / step, exact for a power of two.
void quantiseFaces(float origin, float step, float inverse, float lo, float hi, out uint qlo, out uint qhi) {
  qlo = uint(clamp(floor((lo - origin) * inverse), 0.0, 255.0));
  if (qlo > 0u && origin + float(qlo) * step > lo) --qlo;
  qhi = uint(clamp(ceil((hi - origin) * inverse), 0.0, 255.0));
  if (qhi < 255u && origin + float(qhi) * step < hi) ++qhi;
}

// Writes the quantised form of two children's exact boxes into `node`'s box
// fields, its refit arrivals cleared; children and parent are left as they are.
void encodeNode(inout BvhNode node, vec3 lo0, vec3 hi0, vec3 lo1, vec3 hi1) {
  bool full0 = all(lessThanEqual(lo0, hi0)), full1 = all(lessThanEqual(lo1, hi1));
  vec3 lo = full0 ? (full1 ? min(lo0, lo1) : lo0) : lo1;
  vec3 hi = full0 ? (full1 ? max(hi0, hi1) : hi0) : hi1;
  uint bytes[12];
  if (!full0 && !full1) {
    lo = vec3(0.0);
    hi = vec3(0.0);
  }
  uint e[3];
  for (uint k = 0u; k < 3u; ++k) {
    node.origin[k] = lo[k];
    e[k] = stepExponent(lo[k], hi[k]);
  }
  node.scale = e[0] | (e[1] << 8) | (e[2] << 16);
  vec3 step = nodeStep(node.scale);
  for (uint k = 0u; k < 3u; ++k) {
    float inverse = uintBitsToFloat((254u - e[k]) << 23);  // 2^(127 - e): step's exact reciprocal
    quantiseFaces(lo[k], step[k], inverse, lo0[k], hi0[k], bytes[k], bytes[3u + k]);
    quantiseFaces(lo[k], step[k], inverse, lo1[k], hi1[k], bytes[6u + k], bytes[9u + k]);
  }
  // An empty child: low steps above high ones.
  if (!full0) {
    bytes[0] = 255u;
    bytes[3] = 0u;
  }
  if (!full1) {
    bytes[6] = 255u;
    bytes[9] = 0u;
  }
  for (uint w = 0u; w < 3u; ++w) {
    node.quant[w] = bytes[4u * w] | (bytes[4u * w + 1u] << 8) | (bytes[4u * w + 2u] << 16) | (bytes[4u * w + 3u] << 24);
  }
}

// Two children's exact boxes as the trace reads them: lo0 hi0 lo1 hi1 in three
// vec4s. An empty child is the point at +infinity on every axis: every slab
// then puts its entry at +infinity or its exit at -infinity, so no ray enters.
void packChildBoxes(vec3 lo0, vec3 hi0, vec3 lo1, vec3 hi1, out vec4 a, out vec4 b, out vec4 c) {
  if (!all(lessThanEqual(lo0, hi0))) lo0 = hi0 = vec3(kBvhInfinity);
  if (!all(lessThanEqual(lo1, hi1))) lo1 = hi1 = vec3(kBvhInfinity);
  a = vec4(lo0, hi0.x);
  b = vec4(hi0.yz, lo1.xy);
  c = vec4(lo1.z, hi1);
}
