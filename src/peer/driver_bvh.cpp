// The driver's acceleration structures, through the extension's entry points.
#include "peer/driver_bvh.h"

#include "vk/error.h"

#include <algorithm>

namespace snell::peer {

namespace {

template <typename Function>
Function deviceFunction(vk::Context& context, const char* name) {
  auto f = reinterpret_cast<Function>(vkGetDeviceProcAddr(context.device(), name));
  if (!f) throw vk::VulkanError(std::string("the driver has no ") + name);
  return f;
}

// Builds read their inputs and write the structure: order them against
// everything before and after (a benchmark times them one by one).
void fence(vk::Commands& commands) {
  commands.barrier(VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                   VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
}

VkDeviceAddress structureAddress(vk::Context& context, VkAccelerationStructureKHR structure) {
  auto addressOf = deviceFunction<PFN_vkGetAccelerationStructureDeviceAddressKHR>(
      context, "vkGetAccelerationStructureDeviceAddressKHR");
  VkAccelerationStructureDeviceAddressInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  info.accelerationStructure = structure;
  return addressOf(context.device(), &info);
}

VkDeviceSize scratchAlignment(vk::Context& context) {
  VkPhysicalDeviceAccelerationStructurePropertiesKHR properties{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &properties};
  vkGetPhysicalDeviceProperties2(context.physicalDevice(), &props);
  return std::max<VkDeviceSize>(properties.minAccelerationStructureScratchOffsetAlignment, 1);
}

// A build (or update) of one geometry, as sized and as recorded; the caller
// names the structures and the scratch.
VkAccelerationStructureBuildGeometryInfoKHR geometryInfo(VkAccelerationStructureTypeKHR type,
                                                         VkBuildAccelerationStructureFlagsKHR flags,
                                                         const VkAccelerationStructureGeometryKHR& geometry,
                                                         bool update = false) {
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = type;
  info.flags = flags;
  info.mode = update ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.geometryCount = 1;
  info.pGeometries = &geometry;
  return info;
}

}  // namespace

DriverStructure::DriverStructure(vk::Context& context, VkAccelerationStructureTypeKHR type, VkDeviceSize bytes,
                                 VkDeviceSize scratchBytes, const std::string& name)
    : context_(context) {
  auto create = deviceFunction<PFN_vkCreateAccelerationStructureKHR>(context, "vkCreateAccelerationStructureKHR");
  destroy_ = deviceFunction<PFN_vkDestroyAccelerationStructureKHR>(context, "vkDestroyAccelerationStructureKHR");
  VkDeviceSize alignment = scratchAlignment(context);
  storage_ = vk::Buffer(context, {bytes,
                                  VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR |
                                      VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                                  vk::MemoryDomain::Device, name, true});
  scratch_ = vk::Buffer(context, {scratchBytes + alignment,
                                  VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                                  vk::MemoryDomain::Device, name + " scratch", true});
  scratchAddress_ = (scratch_.address() + alignment - 1) / alignment * alignment;
  VkAccelerationStructureCreateInfoKHR createInfo{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  createInfo.buffer = storage_.handle();
  createInfo.size = bytes;
  createInfo.type = type;
  VK_CHECK(create(context.device(), &createInfo, nullptr, &structure_));
  address_ = structureAddress(context, structure_);
}

DriverStructure::~DriverStructure() {
  if (!structure_) return;
  VkDevice device = context_.device();
  VkAccelerationStructureKHR structure = structure_;
  PFN_vkDestroyAccelerationStructureKHR destroy = destroy_;
  context_.retire([device, structure, destroy] { destroy(device, structure, nullptr); });
}

DriverBlas::DriverBlas(vk::Context& context, const vk::Buffer& positions, uint32_t vertexCount,
                       const vk::Buffer& indices, uint32_t triangleCount, DriverBuild mode, uint32_t firstTriangle)
    : triangleCount_(triangleCount) {
  if (!context.caps().driverAccelerationStructures) {
    throw vk::VulkanError("this device offers no driver acceleration structures (VK_KHR_acceleration_structure)");
  }
  auto sizesOf = deviceFunction<PFN_vkGetAccelerationStructureBuildSizesKHR>(context, "vkGetAccelerationStructureBuildSizesKHR");
  build_ = deviceFunction<PFN_vkCmdBuildAccelerationStructuresKHR>(context, "vkCmdBuildAccelerationStructuresKHR");

  geometry_.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
  geometry_.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  geometry_.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  VkAccelerationStructureGeometryTrianglesDataKHR& triangles = geometry_.geometry.triangles;
  triangles.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  triangles.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  triangles.vertexData.deviceAddress = positions.address();
  triangles.vertexStride = 12;
  triangles.maxVertex = vertexCount ? vertexCount - 1 : 0;
  triangles.indexType = VK_INDEX_TYPE_UINT32;
  triangles.indexData.deviceAddress = indices.address() + VkDeviceAddress(firstTriangle) * 12;
  flags_ = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR |
           (mode == DriverBuild::FastBuild ? VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR
                                           : VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR);

  VkAccelerationStructureBuildGeometryInfoKHR info =
      geometryInfo(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, flags_, geometry_);
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  sizesOf(context.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, &triangleCount_, &sizes);
  structureBytes_ = sizes.accelerationStructureSize;

  structure_ = std::make_unique<DriverStructure>(context, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                 sizes.accelerationStructureSize,
                                                 std::max(sizes.buildScratchSize, sizes.updateScratchSize),
                                                 "driver acceleration structure");
}

void DriverBlas::recordBuild(vk::Commands& commands) { record(commands, false); }

void DriverBlas::recordUpdate(vk::Commands& commands) { record(commands, true); }

VkAccelerationStructureBuildGeometryInfoKHR DriverBlas::buildInfo(bool update) const {
  VkAccelerationStructureBuildGeometryInfoKHR info =
      geometryInfo(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, flags_, geometry_, update);
  info.srcAccelerationStructure = update ? structure_->handle() : VK_NULL_HANDLE;
  info.dstAccelerationStructure = structure_->handle();
  info.scratchData.deviceAddress = structure_->scratchAddress();
  return info;
}

void DriverBlas::record(vk::Commands& commands, bool update) { recordBatch(commands, {this}, update); }

void DriverBlas::recordBatch(vk::Commands& commands, const std::vector<DriverBlas*>& structures, bool update) {
  if (structures.empty()) return;
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
  std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;
  for (const DriverBlas* b : structures) {
    infos.push_back(b->buildInfo(update));
    ranges.push_back({b->triangleCount_, 0, 0, 0});
  }
  std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> rangePointers;
  for (const VkAccelerationStructureBuildRangeInfoKHR& r : ranges) rangePointers.push_back(&r);
  fence(commands);
  structures.front()->build_(commands.handle(), static_cast<uint32_t>(infos.size()), infos.data(), rangePointers.data());
  fence(commands);
}

namespace {

VkAccelerationStructureGeometryKHR instanceGeometry(const vk::Buffer& instances) {
  VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  geometry.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  geometry.geometry.instances.data.deviceAddress = instances.address();
  return geometry;
}

VkAccelerationStructureBuildGeometryInfoKHR topLevelInfo(const VkAccelerationStructureGeometryKHR& geometry) {
  return geometryInfo(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR,
                      geometry);
}

}  // namespace

DriverTlas::DriverTlas(vk::Context& context, uint32_t capacity) : capacity_(std::max(capacity, 1u)) {
  if (!context.caps().driverAccelerationStructures) {
    throw vk::VulkanError("this device offers no driver acceleration structures (VK_KHR_acceleration_structure)");
  }
  auto sizesOf = deviceFunction<PFN_vkGetAccelerationStructureBuildSizesKHR>(context, "vkGetAccelerationStructureBuildSizesKHR");
  build_ = deviceFunction<PFN_vkCmdBuildAccelerationStructuresKHR>(context, "vkCmdBuildAccelerationStructuresKHR");
  instances_ = vk::Buffer(context, {capacity_ * sizeof(VkAccelerationStructureInstanceKHR),
                                    kDriverInputUsage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryDomain::Device,
                                    "driver top-level instances", true});
  VkAccelerationStructureGeometryKHR geometry = instanceGeometry(instances_);
  VkAccelerationStructureBuildGeometryInfoKHR info = topLevelInfo(geometry);
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  sizesOf(context.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, &capacity_, &sizes);
  structure_ = std::make_unique<DriverStructure>(context, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR,
                                                 sizes.accelerationStructureSize, sizes.buildScratchSize,
                                                 "driver top level");
}

void DriverTlas::recordBuild(vk::Commands& commands, uint32_t count) {
  if (count > capacity_) throw vk::VulkanError("driver top level: more instances than it was made for");
  VkAccelerationStructureGeometryKHR geometry = instanceGeometry(instances_);
  VkAccelerationStructureBuildGeometryInfoKHR info = topLevelInfo(geometry);
  info.dstAccelerationStructure = structure_->handle();
  info.scratchData.deviceAddress = structure_->scratchAddress();
  VkAccelerationStructureBuildRangeInfoKHR range{count, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  fence(commands);
  build_(commands.handle(), 1, &info, &ranges);
  fence(commands);
}

}  // namespace snell::peer
