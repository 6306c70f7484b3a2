// The thread-to-entry mapping of the build and refit passes (common/dispatch.glsl's
// jobOf): entries are sorted by the first thread each serves, a build entry's
// `base` by default, a refit entry's `threadBase` where the includer defines
// JOB_FIRST so. The includer declares `entries`, and pc.entryCount is their number.
#ifndef JOB_FIRST
#define JOB_FIRST(i) entries[i].base
#endif
#define JOB_COUNT pc.entryCount
#include "../../common/dispatch.glsl"
