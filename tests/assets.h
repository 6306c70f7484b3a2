// Where the third-party glTF models are: ../shared/assets beside the checkout
// (CI always has it). A missing folder fails the test that asks, loudly.
#pragma once

#include <gtest/gtest.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace snell::test {

inline std::filesystem::path assetsDir() {
  // SNELL_ASSETS_DIR in the environment wins: the GPU machine gets a copy elsewhere.
  const char* override = std::getenv("SNELL_ASSETS_DIR");
  std::filesystem::path dir = override ? override : SNELL_ASSETS_DIR;
  if (!std::filesystem::is_directory(dir)) {
    ADD_FAILURE() << "the shared glTF assets are missing: expected " << dir
                  << " (the project's shared/ folder beside the checkout)";
  }
  return dir;
}

/// A model under ../shared/assets/gltf, e.g. model("Cameras/glTF/Cameras.gltf").
inline std::string model(const std::string& relative) { return (assetsDir() / "gltf" / relative).string(); }

/// A fresh empty folder for one test's files, left behind for a look after a
/// failure. ctest runs tests several at once, each in its own process: the
/// running test's own name (parameter index included) keeps two cases of one
/// parameterised test out of each other's folder.
inline std::filesystem::path scratchDir(const std::string& name) {
  std::string unique = name;
  if (const auto* test = ::testing::UnitTest::GetInstance()->current_test_info()) {
    unique += std::string("-") + test->test_suite_name() + "." + test->name();
  }
  for (char& c : unique) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  }
  std::filesystem::path dir = std::filesystem::temp_directory_path() / ("snell-test-" + unique);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace snell::test
