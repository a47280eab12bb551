#pragma once
// A Vulkan context on whatever device this machine has (lavapipe in CI), or none: the test then
// skips, unless PVR_REQUIRE_VULKAN=1 (the test scripts set it), where a missing driver fails it.
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>

#include "pvr/util/error.h"
#include "pvr/vulkan/vulkan_context.h"

namespace pvr::test {

inline std::unique_ptr<VulkanContext> vulkanContextOrSkip() {
  try {
    return std::make_unique<VulkanContext>(VulkanContextOptions());
  } catch (const Error& e) {
    const char* require = std::getenv("PVR_REQUIRE_VULKAN");
    if (require && std::string(require) == "1") ADD_FAILURE() << "no Vulkan device: " << e.what();
    return nullptr;
  }
}

}  // namespace pvr::test
