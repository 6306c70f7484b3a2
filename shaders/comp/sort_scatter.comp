// Radix sort, step 3 of each pass: each workgroup ranks its tile's keys by digit,
// stably, then writes keys and values to the positions the scanned histogram
// gives. Keys are staged through shared memory in digit order first, so that
// neighbouring invocations write neighbouring addresses.
//
// Ranking is the multisplit of Onesweep (Adinets & Merrill 2022, §4.2): within
// a subgroup, ballots over the digit's bits find the lanes holding the same
// digit; per-subgroup digit counters in shared memory carry the count between
// rounds. It never assumes a subgroup size: masks are uvec4 (up to 128 lanes).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/radix_sort.h"

layout(local_size_x_id = kSortSpecWorkgroupSize) in;
layout(constant_id = kSortSpecKeysPerThread) const uint KEYS_PER_THREAD = 8;
layout(constant_id = kSortSpecMaxSubgroups) const uint MAX_SUBGROUPS = 32;
layout(constant_id = kSortSpecKeyWords) const uint KEY_WORDS = 1;
#include "common/workgroup.glsl"

layout(push_constant) uniform Push { SortPush pc; };
layout(std430, binding = kSortBindingKeysIn) readonly buffer KeysIn { uint keysIn[]; };
layout(std430, binding = kSortBindingKeysOut) writeonly buffer KeysOut { uint keysOut[]; };
layout(std430, binding = kSortBindingValuesIn) readonly buffer ValuesIn { uint valuesIn[]; };
layout(std430, binding = kSortBindingValuesOut) writeonly buffer ValuesOut { uint valuesOut[]; };
layout(std430, binding = kSortBindingHistogram) readonly buffer Histogram { uint histogram[]; };

const uint kTile = gl_WorkGroupSize.x * KEYS_PER_THREAD;
shared uint sSubgroupDigits[MAX_SUBGROUPS * kSortRadix];  // [subgroup][digit] counts, then offsets
shared uint sDigitStart[kSortRadix];   // first tile-local position of each digit
shared uint sDigitOutput[kSortRadix];  // first output position of this tile's keys of each digit
shared uint sExchange[kTile];

uint popcount4(uvec4 m) {
  return bitCount(m.x) + bitCount(m.y) + bitCount(m.z) + bitCount(m.w);
}

void main() {
  uint block = blockIndex();
  if (block >= pc.blockCount) return;  // uniform per workgroup
  uint r = scanOrderIndex();
  uint word = pc.shift >> 5;
  uint bit = pc.shift & 31u;

  for (uint i = r; i < gl_NumSubgroups * kSortRadix; i += gl_WorkGroupSize.x) sSubgroupDigits[i] = 0;
  barrier();

  // Each subgroup owns a contiguous run of the tile; round i takes one key per lane.
  uint subgroupBase = block * kTile + gl_SubgroupID * gl_SubgroupSize * KEYS_PER_THREAD;
  uint keyLo[KEYS_PER_THREAD];
  uint keyHi[KEYS_PER_THREAD];
  uint digit[KEYS_PER_THREAD];
  uint rank[KEYS_PER_THREAD];
  for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
    uint index = subgroupBase + i * gl_SubgroupSize + gl_SubgroupInvocationID;
    bool inside = index < pc.count;
    keyLo[i] = inside ? keysIn[index * KEY_WORDS] : 0xFFFFFFFFu;
    keyHi[i] = (KEY_WORDS == 2u && inside) ? keysIn[index * KEY_WORDS + 1u] : 0xFFFFFFFFu;
    uint d = (((word == 0u) ? keyLo[i] : keyHi[i]) >> bit) & (kSortRadix - 1u);
    digit[i] = d;
    uvec4 peers = subgroupBallot(true);
    for (uint b = 0; b < kSortRadixBits; ++b) {
      bool set = ((d >> b) & 1u) != 0u;
      uvec4 votes = subgroupBallot(set);
      peers &= set ? votes : ~votes;
    }
    uint below = popcount4(peers & gl_SubgroupLtMask);
    uint same = popcount4(peers);
    uint counter = gl_SubgroupID * kSortRadix + d;
    uint before = sSubgroupDigits[counter];
    subgroupMemoryBarrierShared();
    subgroupBarrier();  // every lane has read its counter before the last peer bumps it
    if (below == same - 1u) sSubgroupDigits[counter] = before + same;
    subgroupMemoryBarrierShared();
    subgroupBarrier();
    rank[i] = before + below;
  }
  barrier();

  // Offsets in (digit, subgroup) order: that order is the stable order of the tile.
  for (uint d = r; d < kSortRadix; d += gl_WorkGroupSize.x) {
    uint running = 0;
    for (uint s = 0; s < gl_NumSubgroups; ++s) {
      uint count = sSubgroupDigits[s * kSortRadix + d];
      sSubgroupDigits[s * kSortRadix + d] = running;
      running += count;
    }
    sDigitStart[d] = running;  // the digit's total for now; scanned below
    sDigitOutput[d] = histogram[d * pc.blockCount + block];
  }
  barrier();
  // kSortRadix digits over the workgroup: a few per invocation, then one scan.
  uint perInvocation = (kSortRadix + gl_WorkGroupSize.x - 1u) / gl_WorkGroupSize.x;
  uint first = r * perInvocation;
  uint runSum = 0;
  for (uint j = 0; j < perInvocation; ++j) {
    if (first + j < kSortRadix) runSum += sDigitStart[first + j];
  }
  uint total;
  uint running = workgroupExclusiveAdd(runSum, total);
  for (uint j = 0; j < perInvocation; ++j) {
    if (first + j < kSortRadix) {
      uint count = sDigitStart[first + j];
      sDigitStart[first + j] = running;
      running += count;
    }
  }
  barrier();

  uint localPosition[KEYS_PER_THREAD];
  for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
    uint d = digit[i];
    localPosition[i] = sDigitStart[d] + sSubgroupDigits[gl_SubgroupID * kSortRadix + d] + rank[i];
  }

  // The word that holds the digit goes first, so each striped slot learns its
  // digit and output position once; the other key word and the value follow it.
  uint output_[KEYS_PER_THREAD];
  for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
    sExchange[localPosition[i]] = (word == 0u) ? keyLo[i] : keyHi[i];
  }
  barrier();
  for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
    uint local = i * gl_WorkGroupSize.x + r;
    uint keyWord = sExchange[local];
    uint d = (keyWord >> bit) & (kSortRadix - 1u);
    output_[i] = sDigitOutput[d] + local - sDigitStart[d];
    if (output_[i] < pc.count) keysOut[output_[i] * KEY_WORDS + word] = keyWord;
  }
  if (KEY_WORDS == 2u) {
    barrier();
    for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
      sExchange[localPosition[i]] = (word == 0u) ? keyHi[i] : keyLo[i];
    }
    barrier();
    for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
      uint local = i * gl_WorkGroupSize.x + r;
      if (output_[i] < pc.count) keysOut[output_[i] * KEY_WORDS + (1u - word)] = sExchange[local];
    }
  }
  barrier();
  for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
    uint index = subgroupBase + i * gl_SubgroupSize + gl_SubgroupInvocationID;
    sExchange[localPosition[i]] = index < pc.count ? valuesIn[index] : 0u;
  }
  barrier();
  for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
    uint local = i * gl_WorkGroupSize.x + r;
    if (output_[i] < pc.count) valuesOut[output_[i]] = sExchange[local];
  }
}
