// Preloaded into the commands the fault tests run under LeakSanitizer.
//
// lavapipe initialises LLVM once per process while the Vulkan loader
// enumerates devices, and the loader unloads the driver at vkDestroyInstance.
// What the driver allocated then is still pointed to by its globals, but once
// they are unmapped LeakSanitizer counts it as leaked, in every command, and a
// real leak of snell's could not be told from it. With dlclose a no-op the
// driver's globals stay mapped, so a leak report names only what snell lost.
// (Debian 12's loader predates VK_LOADER_DISABLE_DYNAMIC_LIBRARY_UNLOADING.)

extern "C" int dlclose(void*) { return 0; }
