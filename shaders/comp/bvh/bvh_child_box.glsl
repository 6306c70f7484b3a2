// A node's child's exact box, by its reference `ref` in the tree of `entry`:
// a leaf's is its primitive's, where the box pass put it (the leaf's place
// among the entry's packed primitives), an internal node's the box H-PLOC
// left for it. The includer declares primBoxes and exact.
void childBox(BvhBuildEntry entry, uint ref, out vec3 lo, out vec3 hi) {
  uint at = (ref & kBvhLeafBit) != 0u ? entry.base + ((ref & ~kBvhLeafBit) - entry.first) : ref;
  if ((ref & kBvhLeafBit) != 0u) {
    lo = vec3(primBoxes[6u * at], primBoxes[6u * at + 1u], primBoxes[6u * at + 2u]);
    hi = vec3(primBoxes[6u * at + 3u], primBoxes[6u * at + 4u], primBoxes[6u * at + 5u]);
  } else {
    lo = vec3(exact[6u * at], exact[6u * at + 1u], exact[6u * at + 2u]);
    hi = vec3(exact[6u * at + 3u], exact[6u * at + 4u], exact[6u * at + 5u]);
  }
}
