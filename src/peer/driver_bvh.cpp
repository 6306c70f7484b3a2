// The driver's acceleration structures, through the extension's entry points.
#include "peer/driver_bvh.h"

#include "vk/error.h"

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

}  // namespace

DriverBlas::DriverBlas(vk::Context& context, const vk::Buffer& positions, uint32_t vertexCount,
                       const vk::Buffer& indices, uint32_t triangleCount, DriverBuild mode)
    : context_(context), triangleCount_(triangleCount) {
  if (!context.caps().driverAccelerationStructures) {
    throw vk::VulkanError("this device offers no driver acceleration structures (VK_KHR_acceleration_structure)");
  }
  auto sizesOf = deviceFunction<PFN_vkGetAccelerationStructureBuildSizesKHR>(context, "vkGetAccelerationStructureBuildSizesKHR");
  auto create = deviceFunction<PFN_vkCreateAccelerationStructureKHR>(context, "vkCreateAccelerationStructureKHR");
  build_ = deviceFunction<PFN_vkCmdBuildAccelerationStructuresKHR>(context, "vkCmdBuildAccelerationStructuresKHR");
  destroy_ = deviceFunction<PFN_vkDestroyAccelerationStructureKHR>(context, "vkDestroyAccelerationStructureKHR");

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
  triangles.indexData.deviceAddress = indices.address();
  flags_ = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR |
           (mode == DriverBuild::FastBuild ? VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR
                                           : VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR);

  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  info.flags = flags_;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.geometryCount = 1;
  info.pGeometries = &geometry_;
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  sizesOf(context.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, &triangleCount_, &sizes);
  structureBytes_ = sizes.accelerationStructureSize;

  VkPhysicalDeviceAccelerationStructurePropertiesKHR properties{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &properties};
  vkGetPhysicalDeviceProperties2(context.physicalDevice(), &props);
  VkDeviceSize alignment = std::max<VkDeviceSize>(properties.minAccelerationStructureScratchOffsetAlignment, 1);

  storage_ = vk::Buffer(context, {sizes.accelerationStructureSize,
                                  VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR |
                                      VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                                  vk::MemoryDomain::Device, "driver acceleration structure", true});
  scratch_ = vk::Buffer(context, {std::max(sizes.buildScratchSize, sizes.updateScratchSize) + alignment,
                                  VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                                  vk::MemoryDomain::Device, "driver acceleration structure scratch", true});
  scratchAddress_ = (scratch_.address() + alignment - 1) / alignment * alignment;

  VkAccelerationStructureCreateInfoKHR createInfo{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  createInfo.buffer = storage_.handle();
  createInfo.size = sizes.accelerationStructureSize;
  createInfo.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  VK_CHECK(create(context.device(), &createInfo, nullptr, &structure_));
}

DriverBlas::~DriverBlas() {
  if (!structure_) return;
  VkDevice device = context_.device();
  VkAccelerationStructureKHR structure = structure_;
  PFN_vkDestroyAccelerationStructureKHR destroy = destroy_;
  context_.retire([device, structure, destroy] { destroy(device, structure, nullptr); });
}

void DriverBlas::recordBuild(vk::Commands& commands) { record(commands, false); }

void DriverBlas::recordUpdate(vk::Commands& commands) { record(commands, true); }

void DriverBlas::record(vk::Commands& commands, bool update) {
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  info.flags = flags_;
  info.mode = update ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.srcAccelerationStructure = update ? structure_ : VK_NULL_HANDLE;
  info.dstAccelerationStructure = structure_;
  info.geometryCount = 1;
  info.pGeometries = &geometry_;
  info.scratchData.deviceAddress = scratchAddress_;
  VkAccelerationStructureBuildRangeInfoKHR range{triangleCount_, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  fence(commands);
  build_(commands.handle(), 1, &info, &ranges);
  fence(commands);
}

}  // namespace snell::peer
