// Where an invocation stands in its dispatch. ComputeProgram::dispatchThreads
// splits a large dispatch over y, because x is limited to 65535 workgroups on
// many devices; these flatten it back.
//
// A dispatch that serves many jobs at once (the meshes a deform or refine
// serves, a build's or refit's BVH entries) gives each job a run of
// invocations, the jobs sorted by their first. An includer that defines
// JOB_FIRST(i) (job i's first invocation) and JOB_COUNT (the number of jobs)
// gets jobOf.
//
// Include it after the shader's local_size layout: a function compiled before
// that declaration reads gl_WorkGroupSize as 1 (glslang gives no error), and
// invocations of one workgroup would share their indices.
#ifndef SNELL_DISPATCH_INDEX
#define SNELL_DISPATCH_INDEX

uint workgroupIndex() {
  return gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
}

uint invocationIndex() {
  return workgroupIndex() * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
}
#endif

// Included again once JOB_FIRST is defined, it adds jobOf.
#if defined(JOB_FIRST) && !defined(SNELL_DISPATCH_JOB_OF)
#define SNELL_DISPATCH_JOB_OF
// The job that invocation t serves: the last one whose first invocation is at
// or below t, by bisection.
uint jobOf(uint t) {
  uint lo = 0u, hi = JOB_COUNT;
  while (hi - lo > 1u) {
    uint mid = (lo + hi) / 2u;
    if (JOB_FIRST(mid) <= t) lo = mid;
    else hi = mid;
  }
  return lo;
}
#endif
