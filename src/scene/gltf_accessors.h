// Internal to the glTF loader: the per-file reading state and accessor
// reading that never touches a byte outside its buffer view.
#pragma once

#include "scene/scene.h"

#include <tiny_gltf.h>

#include <cmath>
#include <string>
#include <vector>

namespace snell::scene::gltf {

// No accessor or image may claim more than this: larger files are refused,
// not allocated (2^28 floats is 1 GiB).
inline constexpr size_t kMaxElements = size_t(1) << 28;

/// Reading state for one file: the parsed model, the scene being built, and
/// the failure path that prefixes every message with the file.
struct Reader {
  const std::string& path;
  const tinygltf::Model& model;
  Scene& scene;

  [[noreturn]] void fail(const std::string& problem) const { throw SceneError(path + ": " + problem); }
  void warn(const std::string& note) const { scene.warnings.push_back(note); }

  template <typename T>
  const T& at(const std::vector<T>& list, int index, const std::string& what, const char* kind) const {
    if (index < 0 || static_cast<size_t>(index) >= list.size()) {
      fail(what + " refers to " + kind + " " + std::to_string(index) + ", which does not exist (the file has " +
           std::to_string(list.size()) + ")");
    }
    return list[static_cast<size_t>(index)];
  }
};

inline std::string label(const std::string& kind, size_t index, const std::string& name) {
  return kind + " " + std::to_string(index) + (name.empty() ? "" : " '" + name + "'");
}

struct AccessorData {
  std::vector<double> values;  // count * components
  size_t count = 0;
  int components = 0;
};

/// Any accessor as doubles: every component type, normalized integers, byte
/// strides, and sparse substitution applied.
AccessorData readAccessor(const Reader& r, int index, const std::string& what);
std::vector<float> readScalars(const Reader& r, int index, const std::string& what);
/// Unsigned integers (indices, joints); floats and normalized types are refused.
std::vector<uint32_t> readIndices(const Reader& r, int index, const std::string& what);

/// N-component float vectors; by default NaN and infinity are refused.
template <int N>
std::vector<glm::vec<N, float>> readVectors(const Reader& r, int index, const std::string& what, bool finite = true) {
  AccessorData data = readAccessor(r, index, what);
  if (data.components != N) r.fail(what + " has " + std::to_string(data.components) + " components; " + std::to_string(N) + " expected");
  std::vector<glm::vec<N, float>> out(data.count);
  for (size_t i = 0; i < data.count; ++i) {
    for (int c = 0; c < N; ++c) {
      double v = data.values[i * N + static_cast<size_t>(c)];
      if (finite && !std::isfinite(v)) r.fail(what + " has a NaN or infinite value at element " + std::to_string(i));
      out[i][c] = static_cast<float>(v);
    }
  }
  return out;
}

}  // namespace snell::scene::gltf
