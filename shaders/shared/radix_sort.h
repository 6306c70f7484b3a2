// Layout shared by the radix-sort shaders (shaders/comp/sort_*.comp) and
// src/render/radix_sort.cpp: binding slots, specialization ids, push constants.
#ifndef SNELL_RADIX_SORT_H
#define SNELL_RADIX_SORT_H
#include "shared_types.h"

SNELL_GPU_BEGIN

SNELL_CONST kSortRadixBits = 8;
SNELL_CONST kSortRadix = 256;  // digits per pass: 1 << kSortRadixBits

// Binding slots of set 0.
SNELL_CONST kSortBindingKeysIn = 0;    // uint[count * keyWords]: a 64-bit key is (lo, hi)
SNELL_CONST kSortBindingKeysOut = 1;   // uint[count * keyWords]
SNELL_CONST kSortBindingValuesIn = 2;  // uint[count]
SNELL_CONST kSortBindingValuesOut = 3; // uint[count]
SNELL_CONST kSortBindingHistogram = 4; // uint[kSortRadix * blockCount], digit-major

// Specialization-constant ids.
SNELL_CONST kSortSpecWorkgroupSize = 0;
SNELL_CONST kSortSpecKeysPerThread = 1;
SNELL_CONST kSortSpecMaxSubgroups = 2;  // workgroup size / the device's smallest subgroup
SNELL_CONST kSortSpecKeyWords = 3;      // 1 for 32-bit keys, 2 for 64-bit keys

// 16 bytes, total: 16 bytes
struct SortPush {
  uint count;       // 4: pairs to sort
  uint blockCount;  // 4: workgroups that cover them
  uint shift;       // 4: lowest key bit of this pass's digit, 0..63
  uint pad0;        // 4
};

SNELL_GPU_END
#endif
