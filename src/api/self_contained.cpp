// What a self-contained libsnell.so and Python module (SNELL_SELF_CONTAINED, for the Blender extension's
// wheels) supply themselves so that they load where glibc is older than the build machine's.
//
// The static libstdc++ of GCC 12 built on glibc 2.36 calls arc4random (GLIBC_2.36) from
// std::random_device, which every copy of std::runtime_error drags in (cow-string-inst.o) though snell never
// makes one. Defined here, hidden, the call binds to this getentropy (glibc 2.25) instead, and the wheels
// need glibc 2.34 (Debian 12, Ubuntu 22.04, RHEL 9), not 2.36.
#include <unistd.h>

#include <cstdint>
#include <cstdlib>

extern "C" __attribute__((visibility("hidden"))) std::uint32_t arc4random() {
  std::uint32_t value = 0;
  if (getentropy(&value, sizeof value) != 0) std::abort();  // the kernel's entropy cannot fail for 4 bytes
  return value;
}
