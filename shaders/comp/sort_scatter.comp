// Radix sort, step 3 of each pass: each workgroup ranks its tile's keys by digit,
// stably, then writes keys and values to the positions the scanned histogram
// gives. Keys are staged through shared memory in digit order first, so that
// neighbouring invocations write neighbouring addresses.
//
// Ranking is the multisplit of Onesweep (Adinets & Merrill 2022, §4.2): within
// a subgroup, ballots over the digit's bits find the lanes holding the same
// digit; per-subgroup digit counters in shared memory carry the count between
// rounds. It never assumes a subgroup size: masks are uvec4 (up to 128 lanes).
// (subgroupPartitionNV, one match.any on NVIDIA, measured 27% slower on an H200.)
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "../shared/radix_sort.h"

layout(local_size_x_id = kSortSpecWorkgroupSize) in;
layout(constant_id = kSortSpecKeysPerThread) const uint KEYS_PER_THREAD = 8;
layout(constant_id = kSortSpecMaxSubgroups) const uint MAX_SUBGROUPS = 32;
layout(constant_id = kSortSpecKeyWords) const uint KEY_WORDS = 1;
#include "../common/workgroup.glsl"

layout(push_constant) uniform Push { SortPush pc; };
// 64-bit keys are also read and written as uvec2 through a second view of the
// same binding: one 8-byte access instead of two 4-byte ones.
layout(std430, binding = kSortBindingKeysIn) readonly buffer KeysIn { uint keysIn[]; };
layout(std430, binding = kSortBindingKeysIn) readonly buffer KeysIn64 { uvec2 keysIn64[]; };
layout(std430, binding = kSortBindingKeysOut) writeonly buffer KeysOut { uint keysOut[]; };
layout(std430, binding = kSortBindingKeysOut) writeonly buffer KeysOut64 { uvec2 keysOut64[]; };
layout(std430, binding = kSortBindingValuesIn) readonly buffer ValuesIn { uint valuesIn[]; };
layout(std430, binding = kSortBindingValuesOut) writeonly buffer ValuesOut { uint valuesOut[]; };
layout(std430, binding = kSortBindingHistogram) readonly buffer Histogram { uint histogram[]; };

const uint kTile = gl_WorkGroupSize.x * KEYS_PER_THREAD;
const uint kDigitsPerInvocation = (kSortRadix + gl_WorkGroupSize.x - 1u) / gl_WorkGroupSize.x;
shared uint sSubgroupDigits[MAX_SUBGROUPS * kSortRadix];  // [subgroup][digit] counts, then offsets
shared uint sDigitStart[kSortRadix];  // first tile-local position of each digit
shared uint sDigitShift[kSortRadix];  // output position minus tile-local position, per digit (wraps)
// Keys, then values, staged in digit order through one buffer; the high words
// of 64-bit keys have their own.
shared uint sStaged[kTile];
shared uint sStagedHi[(KEY_WORDS - 1u) * kTile + 1u];

uint popcount4(uvec4 m) {
  return bitCount(m.x) + bitCount(m.y) + bitCount(m.z) + bitCount(m.w);
}

uint digitOf(uvec2 key, uint word, uint bit) {
  return (((word == 0u) ? key.x : key.y) >> bit) & (kSortRadix - 1u);
}

uvec2 loadKey(uint index) {
  if (index >= pc.count) return uvec2(0xFFFFFFFFu);  // padding sorts last in every pass
  return KEY_WORDS == 2u ? keysIn64[index] : uvec2(keysIn[index], 0xFFFFFFFFu);
}

void main() {
  uint block = workgroupIndex();
  if (block >= pc.blockCount) return;  // uniform per workgroup
  uint r = scanOrderIndex();
  // A constant 0 for 32-bit keys lets the compiler drop every high-word path.
  uint word = KEY_WORDS == 1u ? 0u : (pc.shift >> 5);
  uint bit = pc.shift & 31u;

  // Where this tile's keys of each digit go: loaded now, used after ranking,
  // so the scattered reads overlap the work in between.
  uint digitOutput[kDigitsPerInvocation];
  [[unroll]] for (uint j = 0; j < kDigitsPerInvocation; ++j) {
    uint d = r * kDigitsPerInvocation + j;
    digitOutput[j] = d < kSortRadix ? histogram[d * pc.blockCount + block] : 0u;
  }

  for (uint i = r; i < gl_NumSubgroups * kSortRadix; i += gl_WorkGroupSize.x) sSubgroupDigits[i] = 0;
  barrier();

  // Each subgroup owns a contiguous run of the tile; round i takes one key per lane.
  // Registers bound occupancy here (NVIDIA: 118 of them with whole keys and
  // positions at 16 keys each), so only digits (8 bits) and ranks (16 bits:
  // a tile holds at most 65536 keys) are kept, packed; keys are read again,
  // from cache, when they are staged.
  uint subgroupBase = block * kTile + gl_SubgroupID * gl_SubgroupSize * KEYS_PER_THREAD;
  uint digits[(KEYS_PER_THREAD + 3u) / 4u];
  uint ranks[(KEYS_PER_THREAD + 1u) / 2u];
  [[unroll]] for (uint i = 0; i < KEYS_PER_THREAD; i += 4u) digits[i / 4u] = 0u;
  [[unroll]] for (uint i = 0; i < KEYS_PER_THREAD; i += 2u) ranks[i / 2u] = 0u;
  [[unroll]] for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
    uint index = subgroupBase + i * gl_SubgroupSize + gl_SubgroupInvocationID;
    uint keyWord = index < pc.count ? keysIn[index * KEY_WORDS + word] : 0xFFFFFFFFu;
    digits[i / 4u] |= ((keyWord >> bit) & (kSortRadix - 1u)) << (8u * (i % 4u));
  }
  [[unroll]] for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
    uint d = (digits[i / 4u] >> (8u * (i % 4u))) & (kSortRadix - 1u);
    uvec4 peers = subgroupBallot(true);
    [[unroll]] for (uint b = 0; b < kSortRadixBits; ++b) {
      bool set = ((d >> b) & 1u) != 0u;
      uvec4 votes = subgroupBallot(set);
      peers &= set ? votes : ~votes;
    }
    uint below = popcount4(peers & gl_SubgroupLtMask);
    uint same = popcount4(peers);
    uint counter = gl_SubgroupID * kSortRadix + d;
    uint before = sSubgroupDigits[counter];
    subgroupSharedBarrier();  // every lane has read its counter before the last peer bumps it
    if (below == same - 1u) sSubgroupDigits[counter] = before + same;
    subgroupSharedBarrier();
    ranks[i / 2u] |= (before + below) << (16u * (i % 2u));
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
  }
  barrier();
  // kSortRadix digits over the workgroup: a few per invocation, then one scan.
  uint first = r * kDigitsPerInvocation;
  uint runSum = 0;
  [[unroll]] for (uint j = 0; j < kDigitsPerInvocation; ++j) {
    if (first + j < kSortRadix) runSum += sDigitStart[first + j];
  }
  uint total;
  uint running = workgroupExclusiveAdd(runSum, total);
  [[unroll]] for (uint j = 0; j < kDigitsPerInvocation; ++j) {
    uint d = first + j;
    if (d < kSortRadix) {
      uint count = sDigitStart[d];
      sDigitStart[d] = running;
      sDigitShift[d] = digitOutput[j] - running;
      running += count;
    }
  }
  barrier();

  // Stage in digit order, then write out striped: within a digit, neighbouring
  // invocations write neighbouring addresses. Keys first, then values.
  uint slotDigits[(KEYS_PER_THREAD + 3u) / 4u];
  [[unroll]] for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
    uint d = (digits[i / 4u] >> (8u * (i % 4u))) & (kSortRadix - 1u);
    uint rank = (ranks[i / 2u] >> (16u * (i % 2u))) & 0xFFFFu;
    uint local = sDigitStart[d] + sSubgroupDigits[gl_SubgroupID * kSortRadix + d] + rank;
    uvec2 key = loadKey(subgroupBase + i * gl_SubgroupSize + gl_SubgroupInvocationID);
    sStaged[local] = key.x;
    if (KEY_WORDS == 2u) sStagedHi[local] = key.y;
  }
  barrier();
  [[unroll]] for (uint i = 0; i < KEYS_PER_THREAD; i += 4u) slotDigits[i / 4u] = 0u;
  [[unroll]] for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
    uint local = i * gl_WorkGroupSize.x + r;
    uvec2 key = uvec2(sStaged[local], KEY_WORDS == 2u ? sStagedHi[local] : 0u);
    uint d = digitOf(key, word, bit);
    slotDigits[i / 4u] |= d << (8u * (i % 4u));
    uint destination = local + sDigitShift[d];
    if (destination < pc.count) {
      if (KEY_WORDS == 2u) {
        keysOut64[destination] = key;
      } else {
        keysOut[destination] = key.x;
      }
    }
  }
  barrier();
  [[unroll]] for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
    uint d = (digits[i / 4u] >> (8u * (i % 4u))) & (kSortRadix - 1u);
    uint rank = (ranks[i / 2u] >> (16u * (i % 2u))) & 0xFFFFu;
    uint local = sDigitStart[d] + sSubgroupDigits[gl_SubgroupID * kSortRadix + d] + rank;
    uint index = subgroupBase + i * gl_SubgroupSize + gl_SubgroupInvocationID;
    sStaged[local] = index < pc.count ? valuesIn[index] : 0u;
  }
  barrier();
  [[unroll]] for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
    uint local = i * gl_WorkGroupSize.x + r;
    uint d = (slotDigits[i / 4u] >> (8u * (i % 4u))) & (kSortRadix - 1u);
    uint destination = local + sDigitShift[d];
    if (destination < pc.count) valuesOut[destination] = sStaged[local];
  }
}
