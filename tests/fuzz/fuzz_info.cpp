// `snell info SCENE`: the loader, then the summary it prints (shapes,
// materials, texture memory with mips, the GPU memory a frame needs).
#include "fuzz_input.h"

#include "scene/gltf_loader.h"
#include "scene/scene_summary.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  snell::fuzz::FileSet files(data, size);
  try {
    snell::scene::Scene scene = snell::scene::loadGltf(files.document());
    volatile size_t length = snell::scene::describe(scene).size();
    (void)length;
  } catch (const snell::scene::SceneError&) {
  }
  return 0;
}
