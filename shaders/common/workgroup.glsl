// Workgroup-wide helpers that hold for any subgroup size (lavapipe 8, NVIDIA 32,
// AMD 64) and never wait on another workgroup.
//
// Before including, define the specialization constant MAX_SUBGROUPS: the most
// subgroups one workgroup can hold (its size over the device's smallest subgroup).
// Pipelines are created with REQUIRE_FULL_SUBGROUPS, so (gl_SubgroupID,
// gl_SubgroupInvocationID) numbers the invocations densely; that numbering, not
// gl_LocalInvocationIndex, is the order every scan here follows.

#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_memory_scope_semantics : require
#include "dispatch.glsl"

shared uint sSubgroupSums[MAX_SUBGROUPS];
shared uint sWorkgroupTotal;

// Dense invocation number in scan order, 0 .. workgroup size - 1.
uint scanOrderIndex() {
  return gl_SubgroupID * gl_SubgroupSize + gl_SubgroupInvocationID;
}

// Execution barrier for the subgroup that orders its shared-memory accesses
// only. GLSL's subgroupBarrier() also orders global memory, which NVIDIA's
// compiler turns into a fence that waits for every outstanding load and store.
void subgroupSharedBarrier() {
  controlBarrier(gl_ScopeSubgroup, gl_ScopeSubgroup, gl_StorageSemanticsShared, gl_SemanticsAcquireRelease);
}

// Exclusive prefix sum of one value per invocation, in scanOrderIndex() order.
// Every invocation of the workgroup must call it (it holds barriers).
uint workgroupExclusiveAdd(uint value, out uint total) {
  uint inclusive = subgroupInclusiveAdd(value);
  if (gl_SubgroupInvocationID == gl_SubgroupSize - 1) {
    sSubgroupSums[gl_SubgroupID] = inclusive;
  }
  barrier();
  if (gl_SubgroupID == 0) {
    // One subgroup scans the per-subgroup sums, a subgroup-width chunk at a time,
    // because there may be more subgroups than lanes (lavapipe: 32 of 8 lanes).
    uint carry = 0;
    for (uint base = 0; base < gl_NumSubgroups; base += gl_SubgroupSize) {
      uint i = base + gl_SubgroupInvocationID;
      uint sum = i < gl_NumSubgroups ? sSubgroupSums[i] : 0u;
      uint chunkInclusive = subgroupInclusiveAdd(sum);
      if (i < gl_NumSubgroups) {
        sSubgroupSums[i] = carry + chunkInclusive - sum;
      }
      carry += subgroupAdd(sum);
    }
    if (gl_SubgroupInvocationID == 0) {
      sWorkgroupTotal = carry;
    }
  }
  barrier();
  uint result = sSubgroupSums[gl_SubgroupID] + inclusive - value;
  total = sWorkgroupTotal;
  barrier();  // the shared sums may be reused by the next call
  return result;
}
