// The glTF loader on anything: .gltf and .glb, with external buffers and
// images. A file may be refused (SceneError); any other exception, crash,
// sanitizer report, leak or hang is a defect.
#include "fuzz_input.h"

#include "scene/gltf_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  snell::fuzz::FileSet files(data, size);
  try {
    snell::scene::loadGltf(files.document());
  } catch (const snell::scene::SceneError&) {
  }
  return 0;
}
