// libFuzzer harness: mesh import (assimp and photonvr's mapping of its materials, textures and
// lights). The format follows the bytes, as a user's file would: binary glTF by its magic, glTF
// JSON by its opening brace, anything else as OBJ.
#include <cstring>

#include "fuzz_support.h"
#include "pvr/scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const char* extension = "obj";
  if (size >= 4 && std::memcmp(data, "glTF", 4) == 0) extension = "glb";
  else if (size >= 1 && data[0] == '{') extension = "gltf";
  pvr::fuzz::TempInput input(data, size, extension);
  pvr::fuzz::expectCleanFailure([&] { pvr::loadScene(input.path()); });
  return 0;
}
