// libFuzzer target: the OBJ reader and the cloth mesh checks on arbitrary text. Every outcome but a
// mesh or a soak::Error is a bug.
#include <soak/error.hpp>

#include "world/mesh.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const soak::TriangleMesh mesh = soak::parseObjMesh(text, "fuzz.obj");
    soak::validateClothMesh("fuzz", mesh, {}, "fuzz.obj");
  } catch (const soak::Error&) {
  }
  return 0;
}
