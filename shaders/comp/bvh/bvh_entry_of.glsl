// The thread-to-entry mapping of the build and refit passes: entries are
// sorted by the first thread each serves (BVH_ENTRY_FIRST(i): a build
// entry's `base`, the default; a refit entry's `threadBase`), so thread t
// serves the last entry whose first thread is at or below t, found by
// bisection. The includer declares `entries`, and pc.entryCount is their number.
#ifndef BVH_ENTRY_FIRST
#define BVH_ENTRY_FIRST(i) entries[i].base
#endif

uint entryOf(uint t) {
  uint lo = 0u, hi = pc.entryCount;
  while (hi - lo > 1u) {
    uint mid = (lo + hi) / 2u;
    if (BVH_ENTRY_FIRST(mid) <= t) lo = mid;
    else hi = mid;
  }
  return lo;
}
