// `snell`: the command-line front end. Each subcommand lives in its own file.
#include "cli/cli.h"

#include "vk/error.h"

#include <cstdio>
#include <cstdlib>
#include <exception>

namespace snell::cli {

namespace {

constexpr const char* kUsage = R"(snell - refraction through deforming meshes, on Vulkan compute

usage: snell <command> [options]

commands:
  info --devices        list every Vulkan device, which one snell picks and why
  info SCENE.glb        what a glTF file holds and the GPU memory a frame needs
  eye -o EYE.glb        write the procedural eye (see 'snell eye --help')
  render SCENE -o IMG   ray trace a frame (or frames) to PNG/EXR (see 'snell render --help')
  bake SCENE -o MAP     bake a refraction map: the UV behind the glass per pixel (rg16, exr, sky8)
  export-web SCENE -o DIR   a self-contained WebGL page drawing the glass from a sky8 map
  bench sort [options]  time the GPU radix sort (see 'snell bench sort --help')
  bench bvh [scenes]    GPU BVH quality (SAH cost) against a CPU binned-SAH build
  bench frame [options] per-pass GPU time of a frame of the eye
  bench stress          GPU against the CPU reference on the numerical stability grid
  bench scale [options] BVH build and refit times from 1e4 to 1e7 triangles
  bench methods [SCENE] run time against error of each way of drawing refraction
  help                  show this text
  --version             print snell's version

environment:
  SNELL_DEVICE=<index|name>  use this device (an index from 'snell info --devices',
                             or part of its name)
  SNELL_VALIDATION=1         turn on the Khronos validation layer
)";

int runBench(const Args& args) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::printf("usage: snell bench sort|bvh|frame|stress|scale|methods [options]\n\nbenchmarks:\n  sort   GPU radix sort, pairs per second\n"
                "  bvh    SAH cost of the GPU trees against a CPU binned-SAH build\n"
                "  frame  per-pass GPU time of the eye's frame\n"
                "  stress GPU against the CPU reference on the numerical stability grid\n"
                "  scale  BVH build and refit times from 1e4 to 1e7 triangles\n"
                "  methods run time against error of each way of drawing refraction\n");
    return args.empty() ? 2 : 0;
  }
  Args rest(args.begin() + 1, args.end());
  if (args[0] == "sort") return runBenchSort(rest);
  if (args[0] == "bvh") return runBenchBvh(rest);
  if (args[0] == "frame") return runBenchFrame(rest);
  if (args[0] == "stress") return runBenchStress(rest);
  if (args[0] == "scale") return runBenchScale(rest);
  if (args[0] == "methods") return runBenchMethods(rest);
  throw UsageError{"unknown benchmark '" + args[0] + "' (try: sort, bvh, frame, stress, scale, methods)"};
}

}  // namespace

}  // namespace snell::cli

int main(int argc, char** argv) {
  using namespace snell::cli;
  Args args(argv + 1, argv + argc);
  try {
    if (args.empty() || args[0] == "help" || args[0] == "--help" || args[0] == "-h") {
      std::fputs(kUsage, args.empty() ? stderr : stdout);
      return args.empty() ? 2 : 0;
    }
    if (args[0] == "--version" || args[0] == "version") {
      std::printf("snell %s\n", SNELL_VERSION);
      return 0;
    }
    Args rest(args.begin() + 1, args.end());
    if (args[0] == "info") return runInfo(rest);
    if (args[0] == "bench") return runBench(rest);
    if (args[0] == "eye") return runEye(rest);
    if (args[0] == "render") return runRender(rest);
    if (args[0] == "bake") return runBake(rest);
    if (args[0] == "export-web") return runExportWeb(rest);
    throw UsageError{"unknown command '" + args[0] + "'"};
  } catch (const UsageError& e) {
    std::fprintf(stderr, "snell: %s\nRun 'snell help' for usage.\n", e.message.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "snell: error: %s\n", e.what());
    return 1;
  }
}
