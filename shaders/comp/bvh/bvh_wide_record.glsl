// How a completed node writes its share of the 4-wide records (shared/bvh.h,
// BvhWideEntry): its two children into its parent's entries on its own side,
// and a leaf child into its own record, followed by an empty entry. Every
// entry has one writer, so the build's last pass and the refit write records
// as they complete nodes, in any order. The includer declares
// `wideRecords` (vec4[], two a BvhWideEntry) and `pc.flags`.

// Entry `entry` of node slot `node`'s record, the child of `parent`; an empty
// or missing child is the point at +infinity, which no slab enters.
void writeWideEntry(uint node, uint entry, vec3 lo, vec3 hi, uint ref, uint parent) {
  bool full = all(lessThanEqual(lo, hi)) && ref != kBvhNone;
  wideRecords[8u * node + 2u * entry] = vec4(full ? lo : vec3(kBvhInfinity), uintBitsToFloat(full ? ref : kBvhNone));
  wideRecords[8u * node + 2u * entry + 1u] = vec4(full ? hi : vec3(kBvhInfinity), uintBitsToFloat(parent));
}

// Node slot `node`, complete: its children's exact boxes and references, and
// its parent link (BvhNode::parent).
void writeWideShare(uint node, uint parentLink, vec3 lo0, vec3 hi0, vec3 lo1, vec3 hi1, uint child0, uint child1) {
  if ((pc.flags & kBvhFlagWideRecords) == 0u) return;
  if ((child0 & kBvhLeafBit) != 0u) {
    writeWideEntry(node, 0u, lo0, hi0, child0, kBvhNone);
    writeWideEntry(node, 1u, vec3(1.0), vec3(0.0), kBvhNone, kBvhNone);
  }
  if ((child1 & kBvhLeafBit) != 0u) {
    writeWideEntry(node, 2u, lo1, hi1, child1, kBvhNone);
    writeWideEntry(node, 3u, vec3(1.0), vec3(0.0), kBvhNone, kBvhNone);
  }
  if (parentLink == kBvhNone) return;  // a group's root: no record holds its children but its own
  uint parent = parentLink & ~kBvhParentRight;
  uint side = (parentLink & kBvhParentRight) != 0u ? 2u : 0u;
  writeWideEntry(parent, side, lo0, hi0, child0, node);
  writeWideEntry(parent, side + 1u, lo1, hi1, child1, node);
}
