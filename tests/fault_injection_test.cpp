// The fault plan of PVR_INJECT_FAULT (pvr/util/fault_injection.h): what it accepts and refuses,
// and that exactly the planned event of the planned kind fails.
#include <gtest/gtest.h>

#include "pvr/util/error.h"
#include "pvr/util/fault_injection.h"

namespace pvr {
namespace {

TEST(FaultPlan, ParsesEachKindAndItsEvent) {
  EXPECT_FALSE(parseFaultPlan("").active);
  const struct {
    const char* text;
    Fault kind;
    uint64_t event;
  } cases[] = {{"gpu-alloc:1", Fault::GpuAllocation, 1},
               {"gpu-fault:7", Fault::GpuKernelFault, 7},
               {"vk-alloc:12", Fault::VulkanAllocation, 12},
               {"vk-device-lost:100000", Fault::VulkanDeviceLost, 100000}};
  for (const auto& c : cases) {
    const FaultPlan p = parseFaultPlan(c.text);
    EXPECT_TRUE(p.active) << c.text;
    EXPECT_EQ(p.kind, c.kind) << c.text;
    EXPECT_EQ(p.event, c.event) << c.text;
    EXPECT_EQ(std::string(faultName(c.kind)) + ":" + std::to_string(c.event), c.text);
  }
}

TEST(FaultPlan, RefusesMalformedPlans) {
  for (const char* bad : {"gpu-alloc", "gpu-alloc:", "gpu-alloc:0", "gpu-alloc:-3", "gpu-alloc:2x", "GPU-ALLOC:1",
                          "disk-full:1", ":1", "gpu-alloc:1:2", "gpu-alloc: 5", "gpu-alloc:+5",
                          "gpu-alloc:99999999999999999999"}) {
    try {
      parseFaultPlan(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("PVR_INJECT_FAULT must be KIND:N"), std::string::npos) << e.what();
    }
  }
}

// The test process runs without PVR_INJECT_FAULT: events are counted, none fails.
TEST(FaultPlan, WithoutAPlanEventsAreCountedAndNoneFails) {
  ASSERT_FALSE(faultPlan().active);
  const uint64_t before = faultEvents(Fault::VulkanDeviceLost);
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(faultInjected(Fault::VulkanDeviceLost));
  EXPECT_EQ(faultEvents(Fault::VulkanDeviceLost), before + 5);
  EXPECT_EQ(faultPlanReport(), "");
}

}  // namespace
}  // namespace pvr
