#include "pvr/util/fault_injection.h"

#include <array>
#include <atomic>
#include <cstdlib>

#include "pvr/util/error.h"

namespace pvr {
namespace {

constexpr std::array<Fault, 4> kFaults = {Fault::GpuAllocation, Fault::GpuKernelFault, Fault::VulkanAllocation,
                                          Fault::VulkanDeviceLost};

std::array<std::atomic<uint64_t>, 4> gEvents{};

}  // namespace

const char* faultName(Fault kind) {
  switch (kind) {
    case Fault::GpuAllocation: return "gpu-alloc";
    case Fault::GpuKernelFault: return "gpu-fault";
    case Fault::VulkanAllocation: return "vk-alloc";
    case Fault::VulkanDeviceLost: return "vk-device-lost";
  }
  return "?";
}

FaultPlan parseFaultPlan(const std::string& text) {
  FaultPlan plan;
  if (text.empty()) return plan;
  const size_t colon = text.find(':');
  const std::string kind = text.substr(0, colon);
  const std::string count = colon == std::string::npos ? "" : text.substr(colon + 1);
  bool known = false;
  for (Fault f : kFaults)
    if (kind == faultName(f)) plan.kind = f, known = true;
  const bool digits = !count.empty() && count.size() <= 12 &&
                      count.find_first_not_of("0123456789") == std::string::npos;
  const unsigned long long n = digits ? std::strtoull(count.c_str(), nullptr, 10) : 0;
  if (!known || n == 0)
    throw Error("PVR_INJECT_FAULT must be KIND:N with KIND gpu-alloc, gpu-fault, vk-alloc or vk-device-lost and N >= 1, got '" +
                text + "'");
  plan.active = true;
  plan.event = n;
  return plan;
}

const FaultPlan& faultPlan() {
  static const FaultPlan plan = [] {
    const char* text = std::getenv("PVR_INJECT_FAULT");
    return parseFaultPlan(text ? text : "");
  }();
  return plan;
}

bool faultInjected(Fault kind) {
  const uint64_t n = gEvents[size_t(kind)].fetch_add(1, std::memory_order_relaxed) + 1;
  const FaultPlan& plan = faultPlan();
  return plan.active && plan.kind == kind && plan.event == n;
}

uint64_t faultEvents(Fault kind) { return gEvents[size_t(kind)].load(std::memory_order_relaxed); }

std::string faultPlanReport() {
  const FaultPlan& plan = faultPlan();
  if (!plan.active) return "";
  const uint64_t n = faultEvents(plan.kind);
  return std::string("fault plan ") + faultName(plan.kind) + ":" + std::to_string(plan.event) + ": " + std::to_string(n) +
         " " + faultName(plan.kind) + " events, the planned one " +
         (n >= plan.event ? "happened and the run went on" : "did not happen");
}

}  // namespace pvr
