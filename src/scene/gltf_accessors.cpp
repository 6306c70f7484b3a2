// Accessor reading for the glTF loader: component types, normalization,
// strides and sparse substitution, each byte checked against its view.
#include "scene/gltf_accessors.h"

#include <algorithm>
#include <cstring>

namespace snell::scene::gltf {

namespace {

int componentCount(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
  }
}

size_t componentBytes(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

double readComponent(const unsigned char* p, int componentType, bool normalized) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

/// Reads `count` elements of `components` from a buffer view into `out`,
/// refusing any byte outside the view or its buffer.
void readView(const Reader& r, int viewIndex, size_t byteOffset, size_t count, int components, int componentType,
              bool normalized, double* out, const std::string& what) {
  const tinygltf::BufferView& view = r.at(r.model.bufferViews, viewIndex, what, "buffer view");
  const tinygltf::Buffer& buffer = r.at(r.model.buffers, view.buffer, what + "'s buffer view", "buffer");
  size_t size = componentBytes(componentType);
  size_t element = size * static_cast<size_t>(components);
  size_t stride = view.byteStride ? view.byteStride : element;
  if (stride < element) r.fail(what + ": byteStride " + std::to_string(stride) + " is smaller than one element");
  if (count == 0) return;
  if (view.byteOffset > buffer.data.size() || view.byteLength > buffer.data.size() - view.byteOffset) {
    r.fail(what + ": buffer view " + std::to_string(viewIndex) + " runs past the end of its buffer");
  }
  size_t last = byteOffset + stride * (count - 1) + element;  // count is bounded, so no overflow
  if (byteOffset > view.byteLength || last > view.byteLength) {
    r.fail(what + " runs past the end of buffer view " + std::to_string(viewIndex));
  }
  const unsigned char* base = buffer.data.data() + view.byteOffset + byteOffset;
  for (size_t i = 0; i < count; ++i) {
    for (int c = 0; c < components; ++c) {
      out[i * static_cast<size_t>(components) + static_cast<size_t>(c)] =
          readComponent(base + i * stride + static_cast<size_t>(c) * size, componentType, normalized);
    }
  }
}

}  // namespace

AccessorData readAccessor(const Reader& r, int index, const std::string& what) {
  const tinygltf::Accessor& a = r.at(r.model.accessors, index, what, "accessor");
  std::string name = what + " (accessor " + std::to_string(index) + ")";
  AccessorData data;
  data.components = componentCount(a.type);
  if (data.components == 0 || componentBytes(a.componentType) == 0) r.fail(name + " has an unknown type");
  if (a.count > kMaxElements / 16) r.fail(name + " claims " + std::to_string(a.count) + " elements, more than snell accepts");
  data.count = a.count;
  data.values.assign(a.count * static_cast<size_t>(data.components), 0.0);
  if (a.bufferView >= 0) {
    readView(r, a.bufferView, a.byteOffset, a.count, data.components, a.componentType, a.normalized, data.values.data(), name);
  }
  if (a.sparse.isSparse) {
    if (a.sparse.count < 0 || static_cast<size_t>(a.sparse.count) > a.count) r.fail(name + ": sparse count exceeds the accessor's");
    size_t n = static_cast<size_t>(a.sparse.count);
    std::vector<double> indices(n), values(n * static_cast<size_t>(data.components));
    if (componentBytes(a.sparse.indices.componentType) == 0 || a.sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) {
      r.fail(name + ": sparse indices have an invalid component type");
    }
    if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0) r.fail(name + ": negative sparse byteOffset");
    readView(r, a.sparse.indices.bufferView, static_cast<size_t>(a.sparse.indices.byteOffset), n, 1,
             a.sparse.indices.componentType, false, indices.data(), name + " sparse indices");
    readView(r, a.sparse.values.bufferView, static_cast<size_t>(a.sparse.values.byteOffset), n, data.components,
             a.componentType, a.normalized, values.data(), name + " sparse values");
    for (size_t i = 0; i < n; ++i) {
      if (indices[i] >= static_cast<double>(a.count)) r.fail(name + ": sparse index " + std::to_string(indices[i]) + " is out of range");
      size_t target = static_cast<size_t>(indices[i]);
      std::copy_n(values.begin() + static_cast<std::ptrdiff_t>(i * data.components), data.components,
                  data.values.begin() + static_cast<std::ptrdiff_t>(target * data.components));
    }
  }
  return data;
}

std::vector<float> readScalars(const Reader& r, int index, const std::string& what) {
  AccessorData data = readAccessor(r, index, what);
  for (double v : data.values) {
    if (!std::isfinite(v)) r.fail(what + " has a NaN or infinite value");
  }
  return std::vector<float>(data.values.begin(), data.values.end());
}

std::vector<uint32_t> readIndices(const Reader& r, int index, const std::string& what) {
  const tinygltf::Accessor& a = r.at(r.model.accessors, index, what, "accessor");
  // Signed types are refused too (found by fuzzing: a negative index cannot become a uint32_t).
  bool unsignedType = a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                      a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
                      a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  if (!unsignedType || a.normalized) {
    r.fail(what + " must hold unsigned integers (UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT)");
  }
  AccessorData data = readAccessor(r, index, what);
  return std::vector<uint32_t>(data.values.begin(), data.values.end());
}

}  // namespace snell::scene::gltf
