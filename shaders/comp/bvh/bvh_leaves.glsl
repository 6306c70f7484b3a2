// The box of one primitive, as every build and refit computes it. A triangle
// with a non-finite vertex gets an empty box, so it drops out of the tree
// instead of poisoning its ancestors, and is counted (a deform that produced
// NaN should be visible, not silently missing). An instance's box is its
// bottom-level root box carried through its transform (Arvo's method).
// The includer declares positions, indices, instances, blasGroups and dropped.

vec3 vertexPosition(uint v) {
  return vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

void triangleBox(uint t, out vec3 lo, out vec3 hi) {
  vec3 a = vertexPosition(indices[3u * t]), b = vertexPosition(indices[3u * t + 1u]),
       c = vertexPosition(indices[3u * t + 2u]);
  lo = min(a, min(b, c));
  hi = max(a, max(b, c));
  if (!finite3(lo) || !finite3(hi)) {
    emptyBox(lo, hi);
    atomicAdd(dropped, 1u);
  }
}

void instanceBox(uint i, out vec3 lo, out vec3 hi) {
  GpuInstance inst = instances[i];
  BvhGroup g = blasGroups[inst.geometry];
  lo = vec3(g.boxLo[0], g.boxLo[1], g.boxLo[2]);
  hi = vec3(g.boxHi[0], g.boxHi[1], g.boxHi[2]);
  if (g.root == kBvhNone || !all(lessThanEqual(lo, hi))) {
    emptyBox(lo, hi);
    return;
  }
  vec3 centre = 0.5 * (lo + hi), extent = 0.5 * (hi - lo);
  vec3 c, e;
  for (uint r = 0u; r < 3u; ++r) {
    vec4 row = instances[i].objectToWorld[r];
    c[r] = dot(row.xyz, centre) + row.w;
    e[r] = dot(abs(row.xyz), extent);
  }
  lo = c - e;
  hi = c + e;
  if (!finite3(lo) || !finite3(hi)) emptyBox(lo, hi);
}

void primitiveBox(uint prim, out vec3 lo, out vec3 hi) {
  if ((pc.flags & kBvhFlagInstances) != 0u) instanceBox(prim, lo, hi);
  else triangleBox(prim, lo, hi);
}
