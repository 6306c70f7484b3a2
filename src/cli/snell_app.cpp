// The `snell` command line: every subcommand under one CLI11 app, and the
// options that every one of them takes.
#include "cli/commands.h"

#include "io/json.h"
#include "io/version.h"

namespace snell::cli {

std::unique_ptr<CLI::App> makeSnellApp(Runner& run) {
  auto app = std::make_unique<CLI::App>(
      "snell - refraction through deforming meshes, on Vulkan compute.\n"
      "Run 'snell COMMAND --help' for a command's options.",
      "snell");
  app->set_version_flag("--version", std::string("snell ") + io::version());
  app->footer(kHelpFooter);
  app->require_subcommand(1);
  // Options of the parent (--device, --quiet) may follow the subcommand too.
  app->fallthrough();
  // An option given twice keeps the last, as the hand-written parser did and
  // as scripts that append overrides expect (lists say TakeAll themselves).
  app->option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  useSnellHelpFormat(*app);
  addGlobalOptions(*app);
  addInfo(*app, run);
  addEye(*app, run);
  addRender(*app, run);
  addBake(*app, run);
  addExportWeb(*app, run);
  addFarm(*app, run);
  CLI::App* bench = app->add_subcommand("bench", "benchmarks: 'snell bench NAME --help' for each");
  bench->require_subcommand(1);
  bench->footer(kHelpFooter);
  addBenchSort(*bench, run);
  addBenchBvh(*bench, run);
  addBenchFrame(*bench, run);
  addBenchCost(*bench, run);
  addBenchStress(*bench, run);
  addBenchScale(*bench, run);
  addBenchMethods(*bench, run);
  addBenchShot(*bench, run);
  addBenchPipelines(*bench, run);
  return app;
}

}  // namespace snell::cli
