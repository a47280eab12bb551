// libFuzzer harness: trajectory files (--trajectory).
#include "fuzz_support.h"
#include "pvr/app/trajectory.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pvr::fuzz::TempInput input(data, size, "traj");
  pvr::fuzz::expectCleanFailure([&] { pvr::loadTrajectory(input.path()); });
  return 0;
}
