// `snell`: the command-line front end. Each subcommand lives in its own file;
// snell_app.cpp puts them together.
#include "cli/commands.h"

#include "io/json.h"

int main(int argc, char** argv) {
  snell::io::recordCommandLine(argc, argv);
  snell::cli::Runner run;
  std::unique_ptr<CLI::App> app = snell::cli::makeSnellApp(run);
  return snell::cli::runCommandLine(*app, argc, argv, run);
}
