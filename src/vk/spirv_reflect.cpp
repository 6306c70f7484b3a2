// A small SPIR-V reader: only the instructions that decide a compute
// pipeline's layout (SPIR-V 1.6 specification, §2.3 and §3).
#include "vk/spirv_reflect.h"

#include <algorithm>
#include <map>
#include <optional>
#include <stdexcept>
#include <tuple>

namespace snell::vk {

namespace {

// Opcodes and enumerants from the SPIR-V specification.
enum Op : uint32_t {
  OpExecutionMode = 16,
  OpTypeInt = 21,
  OpTypeFloat = 22,
  OpTypeVector = 23,
  OpTypeMatrix = 24,
  OpTypeImage = 25,
  OpTypeSampledImage = 27,
  OpTypeArray = 28,
  OpTypeRuntimeArray = 29,
  OpTypeStruct = 30,
  OpTypePointer = 32,
  OpConstant = 43,
  OpConstantComposite = 44,
  OpSpecConstant = 50,
  OpSpecConstantComposite = 51,
  OpVariable = 59,
  OpDecorate = 71,
  OpMemberDecorate = 72,
  OpExecutionModeId = 331,
};
constexpr uint32_t kDecorationSpecId = 1;
constexpr uint32_t kDecorationBlock = 2;
constexpr uint32_t kDecorationBufferBlock = 3;
constexpr uint32_t kDecorationArrayStride = 6;
constexpr uint32_t kDecorationMatrixStride = 7;
constexpr uint32_t kDecorationBuiltIn = 11;
constexpr uint32_t kDecorationBinding = 33;
constexpr uint32_t kDecorationDescriptorSet = 34;
constexpr uint32_t kDecorationOffset = 35;
constexpr uint32_t kBuiltInWorkgroupSize = 25;
constexpr uint32_t kModeLocalSize = 17;
constexpr uint32_t kModeLocalSizeId = 38;
constexpr uint32_t kStorageUniformConstant = 0;
constexpr uint32_t kStorageUniform = 2;
constexpr uint32_t kStoragePushConstant = 9;
constexpr uint32_t kStorageStorageBuffer = 12;

struct Type {
  uint32_t op = 0;
  std::vector<uint32_t> operands;  // the instruction's words after the result id
};

struct Reader {
  std::string name;
  std::map<uint32_t, Type> types;
  std::map<uint32_t, uint32_t> constants;  // id -> value (scalar 32-bit)
  std::map<uint32_t, std::vector<uint32_t>> composites;
  std::map<uint32_t, uint32_t> specIds;
  std::map<uint32_t, uint32_t> bindings, sets, arrayStrides, matrixStrides;
  std::map<uint32_t, std::map<uint32_t, uint32_t>> memberOffsets;
  std::map<uint32_t, bool> blocks, bufferBlocks;
  std::optional<uint32_t> workgroupSizeId;
  std::array<uint32_t, 3> modeLocalSize{1, 1, 1};
  std::optional<std::array<uint32_t, 3>> modeLocalSizeIds;
  struct Variable {
    uint32_t id, pointerType, storage;
  };
  std::vector<Variable> variables;

  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error("SPIR-V of '" + name + "': " + why);
  }

  uint32_t constant(uint32_t id) const {
    auto it = constants.find(id);
    if (it == constants.end()) fail("id " + std::to_string(id) + " is not a 32-bit constant");
    return it->second;
  }

  uint32_t sizeOf(uint32_t typeId, int depth = 0) const {
    if (depth > 16) fail("types nest too deeply");
    auto it = types.find(typeId);
    if (it == types.end()) fail("unknown type id " + std::to_string(typeId));
    const Type& t = it->second;
    switch (t.op) {
      case OpTypeInt:
      case OpTypeFloat:
        return t.operands.at(0) / 8;
      case OpTypeVector:
        return sizeOf(t.operands.at(0), depth + 1) * t.operands.at(1);
      case OpTypeMatrix: {
        auto stride = matrixStrides.find(typeId);
        uint32_t column = stride != matrixStrides.end() ? stride->second : sizeOf(t.operands.at(0), depth + 1);
        return column * t.operands.at(1);
      }
      case OpTypeArray: {
        auto stride = arrayStrides.find(typeId);
        uint32_t element = stride != arrayStrides.end() ? stride->second : sizeOf(t.operands.at(0), depth + 1);
        return element * constant(t.operands.at(1));
      }
      case OpTypeStruct: {
        uint32_t size = 0;
        auto offsets = memberOffsets.find(typeId);
        for (uint32_t m = 0; m < t.operands.size(); ++m) {
          uint32_t offset = 0;
          if (offsets != memberOffsets.end() && offsets->second.count(m)) offset = offsets->second.at(m);
          size = std::max(size, offset + sizeOf(t.operands[m], depth + 1));
        }
        return size;
      }
      default:
        fail("cannot size a type with opcode " + std::to_string(t.op));
    }
  }

  VkDescriptorType descriptorType(const Variable& v) const {
    uint32_t pointee = types.at(v.pointerType).operands.at(1);
    // Arrays of descriptors are typed by their element.
    while (types.count(pointee) && (types.at(pointee).op == OpTypeArray || types.at(pointee).op == OpTypeRuntimeArray)) {
      pointee = types.at(pointee).operands.at(0);
    }
    if (v.storage == kStorageStorageBuffer) return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    if (v.storage == kStorageUniform) {
      return bufferBlocks.count(pointee) ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER : VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    }
    const Type& t = types.at(pointee);
    if (t.op == OpTypeSampledImage) return VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    if (t.op == OpTypeImage) {
      // operands: sampled type, dim, depth, arrayed, ms, sampled (1 = sampled, 2 = storage), format
      return t.operands.at(5) == 2 ? VK_DESCRIPTOR_TYPE_STORAGE_IMAGE : VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
    }
    fail("unsupported descriptor at binding " + std::to_string(bindings.at(v.id)));
  }
};

}  // namespace

ShaderReflection reflectShader(std::span<const uint32_t> spirv, std::span<const SpecConstant> specialization,
                                const std::string& name) {
  Reader r;
  r.name = name;
  if (spirv.size() < 5 || spirv[0] != 0x07230203u) r.fail("not SPIR-V (bad magic number)");
  size_t at = 5;
  while (at < spirv.size()) {
    uint32_t words = spirv[at] >> 16;
    uint32_t op = spirv[at] & 0xFFFFu;
    if (words == 0 || at + words > spirv.size()) r.fail("truncated instruction at word " + std::to_string(at));
    std::span<const uint32_t> in = spirv.subspan(at + 1, words - 1);
    switch (op) {
      case OpExecutionMode:
        if (in.size() >= 5 && in[1] == kModeLocalSize) r.modeLocalSize = {in[2], in[3], in[4]};
        break;
      case OpExecutionModeId:
        if (in.size() >= 5 && in[1] == kModeLocalSizeId) r.modeLocalSizeIds = std::array<uint32_t, 3>{in[2], in[3], in[4]};
        break;
      case OpTypeInt:
      case OpTypeFloat:
      case OpTypeVector:
      case OpTypeMatrix:
      case OpTypeImage:
      case OpTypeSampledImage:
      case OpTypeArray:
      case OpTypeRuntimeArray:
      case OpTypeStruct:
      case OpTypePointer:
        if (in.empty()) r.fail("type without a result id");
        r.types[in[0]] = Type{op, std::vector<uint32_t>(in.begin() + 1, in.end())};
        break;
      case OpConstant:
      case OpSpecConstant:
        if (in.size() >= 3) r.constants[in[1]] = in[2];
        break;
      case OpConstantComposite:
      case OpSpecConstantComposite:
        if (in.size() >= 2) r.composites[in[1]] = std::vector<uint32_t>(in.begin() + 2, in.end());
        break;
      case OpVariable:
        if (in.size() >= 3) r.variables.push_back({in[1], in[0], in[2]});
        break;
      case OpDecorate:
        if (in.size() >= 2) {
          uint32_t target = in[0], decoration = in[1];
          uint32_t literal = in.size() >= 3 ? in[2] : 0;
          if (decoration == kDecorationSpecId) r.specIds[target] = literal;
          if (decoration == kDecorationBinding) r.bindings[target] = literal;
          if (decoration == kDecorationDescriptorSet) r.sets[target] = literal;
          if (decoration == kDecorationArrayStride) r.arrayStrides[target] = literal;
          if (decoration == kDecorationMatrixStride) r.matrixStrides[target] = literal;
          if (decoration == kDecorationBlock) r.blocks[target] = true;
          if (decoration == kDecorationBufferBlock) r.bufferBlocks[target] = true;
          if (decoration == kDecorationBuiltIn && literal == kBuiltInWorkgroupSize) r.workgroupSizeId = target;
        }
        break;
      case OpMemberDecorate:
        if (in.size() >= 4 && in[2] == kDecorationOffset) r.memberOffsets[in[0]][in[1]] = in[3];
        break;
      default:
        break;
    }
    at += words;
  }

  // Apply the pipeline's specialization to every spec constant that has an id.
  for (const auto& [id, specId] : r.specIds) {
    for (const SpecConstant& s : specialization) {
      if (s.id == specId) r.constants[id] = s.value;
    }
  }

  ShaderReflection out;
  if (r.workgroupSizeId) {
    auto composite = r.composites.find(*r.workgroupSizeId);
    if (composite == r.composites.end() || composite->second.size() != 3) r.fail("WorkgroupSize is not a 3-vector");
    for (int i = 0; i < 3; ++i) out.localSize[i] = r.constant(composite->second[i]);
  } else if (r.modeLocalSizeIds) {
    for (int i = 0; i < 3; ++i) out.localSize[i] = r.constant((*r.modeLocalSizeIds)[i]);
  } else {
    out.localSize = r.modeLocalSize;
  }

  for (const Reader::Variable& v : r.variables) {
    if (v.storage == kStoragePushConstant) {
      out.pushConstantBytes = r.sizeOf(r.types.at(v.pointerType).operands.at(1));
    } else if (v.storage == kStorageStorageBuffer || v.storage == kStorageUniform || v.storage == kStorageUniformConstant) {
      if (!r.bindings.count(v.id)) continue;
      out.bindings.push_back({r.sets.count(v.id) ? r.sets.at(v.id) : 0, r.bindings.at(v.id), r.descriptorType(v)});
    }
  }
  std::sort(out.bindings.begin(), out.bindings.end(),
            [](const ReflectedBinding& a, const ReflectedBinding& b) { return std::tie(a.set, a.binding) < std::tie(b.set, b.binding); });
  // Several views of one buffer (uint[] and uvec2[], say) share a binding: keep one.
  auto same = [](const ReflectedBinding& a, const ReflectedBinding& b) { return a.set == b.set && a.binding == b.binding; };
  for (size_t i = 1; i < out.bindings.size(); ++i) {
    if (same(out.bindings[i - 1], out.bindings[i]) && out.bindings[i - 1].type != out.bindings[i].type) {
      r.fail("binding " + std::to_string(out.bindings[i].binding) + " is declared with two descriptor types");
    }
  }
  out.bindings.erase(std::unique(out.bindings.begin(), out.bindings.end(), same), out.bindings.end());
  return out;
}

}  // namespace snell::vk
