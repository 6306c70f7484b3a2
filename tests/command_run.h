// Runs a program as a user would from a shell, for the command-line tests.
#pragma once

#include <array>
#include <cstdio>
#include <memory>
#include <string>
#include <sys/wait.h>

namespace snell::test {

struct CommandRun {
  int exitCode;
  std::string output;  // stdout and stderr together
};

/// Runs `commandLine` through the shell; -1 as the exit code when it did not exit normally.
inline CommandRun runCommand(const std::string& commandLine) {
  std::string command = commandLine + " 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  std::string output;
  std::array<char, 4096> buffer;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe.get())) output.append(buffer.data(), n);
  int status = pclose(pipe.release());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

/// `snell ARGUMENTS`: the build's own binary (SNELL_BINARY, which every test
/// target is given), run as runCommand runs a command line.
inline CommandRun snell(const std::string& arguments) { return runCommand(std::string(SNELL_BINARY) + " " + arguments); }

inline std::string shellQuoted(const std::string& path) { return "'" + path + "'"; }

}  // namespace snell::test
