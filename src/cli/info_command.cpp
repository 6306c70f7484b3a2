// `snell info --devices`: the device table, and the verdict on each device.
#include "cli/cli.h"

#include "vk/context.h"

#include <cstdio>

namespace snell::cli {

int runInfo(const Args& args) {
  if (args.size() == 1 && (args[0] == "--help" || args[0] == "-h")) {
    std::printf("usage: snell info --devices\n\n  --devices   list Vulkan devices, the one snell picks, and why\n");
    return 0;
  }
  if (args.size() != 1 || args[0] != "--devices") {
    throw UsageError{"info expects --devices (scene files come in a later version)"};
  }
  vk::DeviceReport report = vk::surveyDevices();
  std::printf("Vulkan devices%s:\n%s", report.override.empty() ? "" : (" (SNELL_DEVICE=" + report.override + ")").c_str(),
              report.table().c_str());
  if (!report.choice.chosen) {
    std::fprintf(stderr, "snell: error: no device meets snell's requirements (see the reasons above)\n");
    return 1;
  }
  std::printf("snell uses [%u] %s\n", report.devices[*report.choice.chosen].index,
              report.devices[*report.choice.chosen].name.c_str());
  return 0;
}

}  // namespace snell::cli
