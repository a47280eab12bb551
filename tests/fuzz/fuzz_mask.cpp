// libFuzzer harness: foveation mask files (`photonvr mask`'s output, loaded with --mask).
#include "fuzz_support.h"
#include "pvr/foveation/mask.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pvr::fuzz::TempInput input(data, size, "mask");
  pvr::fuzz::expectCleanFailure([&] { pvr::loadFoveationMask(input.path()); });
  return 0;
}
