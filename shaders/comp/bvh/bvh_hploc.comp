// Build step 4, after the sort: H-PLOC (Benthin, Meister, Barczak, Mehalwal,
// Tsakok and Kensler, HPG 2024). Every invocation starts at one sorted leaf
// and climbs Apetrei's bottom-up LBVH over the keys: at each level it meets
// the neighbouring range at the split with the more alike keys; the first to
// arrive there stops, the second carries on with both ranges (an atomic
// exchange, acquire/release, so it sees what the first left behind). Once a
// range spans more than half a window of leaves, the invocation's subgroup
// (its team) loads the range's clusters (at most half a window from each
// side) and merges them PLOC-style, mutual nearest neighbours by the surface
// area of their union within a search radius, until half a window is left;
// at a group's root it merges down to one. Each merge writes its node's
// children and its exact box (bvh_quantise.comp quantises the children's
// boxes once the tree stands, off the team's critical path) to the slot
// max(first position of either cluster) - 1, so the tree and its memory
// layout are the same on every run (shared/bvh.h). No invocation waits for
// another outside its subgroup: a range is only continued by whoever arrives
// second, so it is safe without forward-progress guarantees.
//
// The window has a fixed size whatever the subgroup size (an invocation
// holds several slots where subgroups are narrow), so trees are the same on
// every device given the same keys.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_memory_scope_semantics : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "bvh_common.glsl"

layout(constant_id = kBvhSpecSlots) const uint kSlots = 1u;
layout(constant_id = kBvhSpecTeams) const uint kTeams = 1u;

layout(std430, binding = kBvhBindingBuildEntries) readonly buffer Entries { BvhBuildEntry entries[]; };
layout(std430, binding = kBvhBindingKeys) readonly buffer Keys { uint keys[]; };
layout(std430, binding = kBvhBindingValues) readonly buffer Values { uint values[]; };
layout(std430, binding = kBvhBindingPrimBoxes) readonly buffer PrimBoxes { float primBoxes[]; };
layout(std430, binding = kBvhBindingParentIds) coherent buffer ParentIds { uint parentIds[]; };
layout(std430, binding = kBvhBindingClusters) coherent buffer Clusters { BvhCluster clusters[]; };
layout(std430, binding = kBvhBindingNodes) coherent buffer Nodes { BvhNode nodes[]; };
layout(std430, binding = kBvhBindingExactBoxes) writeonly buffer ExactBoxes { float exact[]; };
layout(std430, binding = kBvhBindingGroups) buffer Groups { BvhGroup groups[]; };

const uint kHalf = kBvhWindow / 2u;

// Each team's window: one cluster per slot (its reference, its first sorted
// position, its box), and the team's task.
shared vec3 sLo[kTeams * kBvhWindow], sHi[kTeams * kBvhWindow];
shared uint sRef[kTeams * kBvhWindow], sFirst[kTeams * kBvhWindow];
shared uint sNearest[kTeams * kBvhWindow], sKeep[kTeams * kBvhWindow];
shared uint sLeftCount[kTeams], sRightCount[kTeams];
shared uint sTaskL[kTeams], sTaskR[kTeams], sTaskSplit[kTeams], sTaskFinal[kTeams], sTaskEntry[kTeams];

uint team, lane, width, w0;  // w0: the first of this team's window slots in shared memory

// Barriers for the team. Within a merge only the window in shared memory
// changes hands. Around one, buffer memory too, at device scope: what the
// owner acquired from other workgroups is seen by every member, and every
// node a member writes happens before the owner's release of the range.
void teamSync() {
  controlBarrier(gl_ScopeSubgroup, gl_ScopeSubgroup, gl_StorageSemanticsShared, gl_SemanticsAcquireRelease);
}

void teamSyncDevice() {
  controlBarrier(gl_ScopeSubgroup, gl_ScopeDevice, gl_StorageSemanticsBuffer | gl_StorageSemanticsShared,
                 gl_SemanticsAcquireRelease);
}

#include "bvh_entry_of.glsl"

uvec2 sortedKey(uint pos) {
  if ((pc.flags & kBvhFlagKeys32) != 0u) return uvec2(keys[pos], 0u);
  return uvec2(keys[2u * pos], keys[2u * pos + 1u]);
}

// The split between sorted positions i and i + 1 ranks below the split after
// j when its keys are more alike: a total order (the keys' XOR, then the XOR
// of the positions, which balances runs of equal keys, then the position).
bool splitBelow(BvhBuildEntry entry, uint i, uint j) {
  uvec2 a = sortedKey(i) ^ sortedKey(i + 1u);
  uvec2 b = sortedKey(j) ^ sortedKey(j + 1u);
  if (a.y != b.y) return a.y < b.y;
  if (a.x != b.x) return a.x < b.x;
  // Positions within the group, so a group's tree does not depend on what else is built with it.
  uint li = i - entry.base, lj = j - entry.base;
  uint ia = li ^ (li + 1u), ib = lj ^ (lj + 1u);
  if (ia != ib) return ia < ib;
  return li < lj;
}

// The leaf at sorted position s: its reference and box.
void leafCluster(BvhBuildEntry entry, uint s, out uint ref, out vec3 lo, out vec3 hi) {
  uint prim = values[s];
  uint t = entry.base + (prim - entry.first);  // where the box pass put its box
  lo = vec3(primBoxes[6u * t], primBoxes[6u * t + 1u], primBoxes[6u * t + 2u]);
  hi = vec3(primBoxes[6u * t + 3u], primBoxes[6u * t + 4u], primBoxes[6u * t + 5u]);
  ref = kBvhLeafBit | prim;
}

void setParent(uint ref, uint parent) {
  if ((ref & kBvhLeafBit) == 0u) nodes[ref].parent = parent;
}

void writeRoot(BvhBuildEntry entry, uint ref, vec3 lo, vec3 hi) {
  uint g = entry.group;
  groups[g].root = ref;
  for (uint k = 0u; k < 3u; ++k) {
    groups[g].boxLo[k] = lo[k];
    groups[g].boxHi[k] = hi[k];
  }
  groups[g].buildArea = boxArea(lo, hi);
  setParent(ref, kBvhNone);
}

// Pairs are ordered by the area of their union, then by their slots, so
// every slot's nearest neighbour is unique and the best pair is mutual.
// Candidates come in ascending slots: on a tie the earlier one is also the
// pair that comes first in that order, so it stands.
uint nearest(uint i, uint count) {
  vec3 lo = sLo[w0 + i], hi = sHi[w0 + i];
  float best = kInf;
  uint bestJ = kBvhNone;
  uint from = i > kBvhSearchRadius ? i - kBvhSearchRadius : 0u;
  uint to = min(count - 1u, i + kBvhSearchRadius);
  for (uint j = from; j <= to; ++j) {
    if (j == i) continue;
    float d = boxArea(min(lo, sLo[w0 + j]), max(hi, sHi[w0 + j]));
    if (bestJ == kBvhNone || d < best) {
      best = d;
      bestJ = j;
    }
  }
  return bestJ;
}

// Clusters the range [L, R] of entry e, whose halves [L, split] and
// [split + 1, R] are final, with the whole team.
void mergeRange(uint L, uint R, uint split, bool final, uint e) {
  BvhBuildEntry entry = entries[e];
  uint sizes[2] = uint[2](split - L + 1u, R - split);
  uint bases[2] = uint[2](L, split + 1u);
  if (lane == 0u) {
    sLeftCount[team] = min(kHalf, sizes[0]);
    sRightCount[team] = min(kHalf, sizes[1]);
  }
  teamSync();
  // Load: slots below half a window from the left range, the rest from the
  // right. A range of more than half a window was clustered and stored; its
  // list ends at the first empty entry. A smaller one is its leaves.
  uint ref[kSlots], first[kSlots];
  vec3 lo[kSlots], hi[kSlots];
  bool valid[kSlots];
  for (uint k = 0u; k < kSlots; ++k) {
    uint i = lane + k * width;
    valid[k] = false;
    if (i >= kBvhWindow) continue;
    uint side = i < kHalf ? 0u : 1u, j = i - side * kHalf;
    if (j >= sizes[side]) continue;
    uint at = bases[side] + j;
    if (sizes[side] > kHalf) {
      BvhCluster c = clusters[at];
      if (c.ref == kBvhNone) {
        if (side == 0u) atomicMin(sLeftCount[team], j);
        else atomicMin(sRightCount[team], j);
        continue;
      }
      ref[k] = c.ref;
      first[k] = c.first;
      lo[k] = vec3(c.lo[0], c.lo[1], c.lo[2]);
      hi[k] = vec3(c.hi[0], c.hi[1], c.hi[2]);
    } else {
      first[k] = at;
      leafCluster(entry, at, ref[k], lo[k], hi[k]);
    }
    valid[k] = true;
  }
  teamSync();
  uint leftCount = sLeftCount[team], count = sLeftCount[team] + sRightCount[team];
  for (uint k = 0u; k < kSlots; ++k) {
    uint i = lane + k * width;
    if (i >= kBvhWindow || !valid[k]) continue;
    uint side = i < kHalf ? 0u : 1u, j = i - side * kHalf;
    if (j >= (side == 0u ? leftCount : count - leftCount)) continue;  // past the end of a stored list
    uint at = w0 + (side == 0u ? j : leftCount + j);
    sRef[at] = ref[k];
    sFirst[at] = first[k];
    sLo[at] = lo[k];
    sHi[at] = hi[k];
  }
  teamSync();

  uint target = final ? 1u : kHalf;
  for (uint round = 0u; round < kBvhWindow && count > target; ++round) {
    for (uint k = 0u; k < kSlots; ++k) {
      uint i = lane + k * width;
      if (i < count) sNearest[w0 + i] = nearest(i, count);
    }
    teamSync();
    // Mutual nearest neighbours merge: the lower slot makes the node and
    // keeps the new cluster, the higher slot goes.
    bool keep[kSlots];
    for (uint k = 0u; k < kSlots; ++k) {
      uint i = lane + k * width;
      keep[k] = false;
      if (i >= count) continue;
      uint j = sNearest[w0 + i];
      bool mutual = j < count && sNearest[w0 + j] == i;
      keep[k] = !(mutual && j < i);
      ref[k] = sRef[w0 + i];
      first[k] = sFirst[w0 + i];
      lo[k] = sLo[w0 + i];
      hi[k] = sHi[w0 + i];
      if (mutual && i < j) {
        uint node = entry.first + (max(first[k], sFirst[w0 + j]) - entry.base) - 1u;
        nodes[node].child = uint[2](ref[k], sRef[w0 + j]);
        nodes[node].parent = kBvhNone;
        setParent(ref[k], node);
        setParent(sRef[w0 + j], node | kBvhParentRight);
        ref[k] = node;
        first[k] = min(first[k], sFirst[w0 + j]);
        lo[k] = min(lo[k], sLo[w0 + j]);
        hi[k] = max(hi[k], sHi[w0 + j]);
        for (uint a = 0u; a < 3u; ++a) {
          exact[6u * node + a] = lo[k][a];
          exact[6u * node + 3u + a] = hi[k][a];
        }
      }
      sKeep[w0 + i] = keep[k] ? 1u : 0u;
    }
    teamSync();
    uint kept = 0u;
    uint at[kSlots];
    for (uint k = 0u; k < kSlots; ++k) at[k] = 0u;
    if (kSlots == 1u && width >= kBvhWindow) {
      // One slot a lane: the kept clusters' new places are a ballot's prefix counts.
      uvec4 ballot = subgroupBallot(keep[0]);
      at[0] = subgroupBallotExclusiveBitCount(ballot);
      kept = subgroupBallotBitCount(ballot);
    } else {
      // Narrower subgroups: every lane counts the flags below each of its slots.
      for (uint m = 0u; m < count; ++m) {
        uint keepM = sKeep[w0 + m];
        for (uint k = 0u; k < kSlots; ++k) {
          if (m < lane + k * width) at[k] += keepM;
        }
        kept += keepM;
      }
    }
    teamSync();
    for (uint k = 0u; k < kSlots; ++k) {
      uint i = lane + k * width;
      if (i >= count || !keep[k]) continue;
      sRef[w0 + at[k]] = ref[k];
      sFirst[w0 + at[k]] = first[k];
      sLo[w0 + at[k]] = lo[k];
      sHi[w0 + at[k]] = hi[k];
    }
    count = kept;
    teamSync();
  }

  if (final) {
    if (lane == 0u) writeRoot(entry, sRef[w0], sLo[w0], sHi[w0]);
    return;
  }
  for (uint k = 0u; k < kSlots; ++k) {
    uint i = lane + k * width;
    if (i >= count) continue;
    vec3 l = sLo[w0 + i], h = sHi[w0 + i];
    clusters[L + i] = BvhCluster(sRef[w0 + i], sFirst[w0 + i], float[3](l.x, l.y, l.z), float[3](h.x, h.y, h.z));
  }
  if (lane == 0u && L + count <= R) clusters[L + count].ref = kBvhNone;
}

void main() {
  team = gl_SubgroupID;
  lane = gl_SubgroupInvocationID;
  width = gl_SubgroupSize;
  w0 = team * kBvhWindow;
  uint s = workgroupIndex() * gl_WorkGroupSize.x + team * width + lane;
  bool climbing = s < pc.count;
  uint e = 0u, L = s, R = s, lowest = 0u, highest = 0u, split = 0u;
  bool needMerge = false, final = false;
  if (climbing) {
    e = jobOf(s);
    BvhBuildEntry entry = entries[e];
    lowest = entry.base;
    highest = entry.base + entry.count - 1u;
    if (lowest == highest) {  // a group of one primitive is its own root
      uint ref;
      vec3 lo, hi;
      leafCluster(entry, s, ref, lo, hi);
      writeRoot(entry, ref, lo, hi);
      climbing = false;
    }
  }

  for (uint level = 0u; level < kBvhMaxDepth; ++level) {
    if (subgroupBallot(climbing) == uvec4(0u)) break;
    if (climbing) {
      bool right = L == lowest || (R != highest && splitBelow(entries[e], R, L - 1u));
      split = right ? R : L - 1u;
      // Leave the far end of this range for whoever comes from the other side.
      uint other = atomicExchange(parentIds[split], right ? L : R, gl_ScopeDevice, gl_StorageSemanticsBuffer,
                                  gl_SemanticsAcquireRelease);
      if (other == kBvhNone) {
        climbing = false;  // first here: the sibling range is not done yet
      } else if (right) {
        R = other;
      } else {
        L = other;
      }
      final = climbing && L == lowest && R == highest;
      needMerge = climbing && (final || R - L + 1u > kHalf);
    }
    // The ranges that need clustering, one after another, each by the whole team.
    for (uint round = 0u; round < width; ++round) {
      uvec4 waiting = subgroupBallot(needMerge);
      if (waiting == uvec4(0u)) break;
      uint owner = subgroupBallotFindLSB(waiting);
      if (lane == owner) {
        sTaskL[team] = L;
        sTaskR[team] = R;
        sTaskSplit[team] = split;
        sTaskFinal[team] = final ? 1u : 0u;
        sTaskEntry[team] = e;
        needMerge = false;
        if (final) climbing = false;
      }
      teamSyncDevice();
      mergeRange(sTaskL[team], sTaskR[team], sTaskSplit[team], sTaskFinal[team] != 0u, sTaskEntry[team]);
      teamSyncDevice();
    }
  }
}
