// Layout shared by the prefix-sum shaders (shaders/comp/scan_*.comp) and
// src/render/prefix_sum.cpp: binding slots, specialization ids, push constants.
#ifndef SNELL_PREFIX_SUM_H
#define SNELL_PREFIX_SUM_H
#include "shared_types.h"

SNELL_GPU_BEGIN

// Binding slots of set 0.
SNELL_CONST kScanBindingData = 0;      // uint[count]: scanned in place
SNELL_CONST kScanBindingPartials = 1;  // uint[blockCount]: one sum per block

// Specialization-constant ids.
SNELL_CONST kScanSpecWorkgroupSize = 0;
SNELL_CONST kScanSpecItemsPerThread = 1;
SNELL_CONST kScanSpecMaxSubgroups = 2;

// 16 bytes, total: 16 bytes
struct ScanPush {
  uint count;       // 4: elements in the data buffer
  uint blockCount;  // 4: workgroups that cover it (partials has this many)
  uint addPartials; // 4: 1 adds partials[block] to the block's scan (step 3), 0 not (step 2)
  uint pad0;        // 4
};

SNELL_GPU_END
#endif
