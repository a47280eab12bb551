// libFuzzer harness: the JSON scene format (docs/scene-format.md) through loadScene.
#include "fuzz_support.h"
#include "pvr/scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pvr::fuzz::TempInput input(data, size, "json");
  pvr::fuzz::expectCleanFailure([&] { pvr::loadScene(input.path()); });
  return 0;
}
