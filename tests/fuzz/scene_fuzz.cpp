// libFuzzer target: the scene loader on arbitrary text. Every outcome but a scene or a soak::Error (a
// crash, a sanitizer report, another exception, a hang) is a bug. The memory budget is set low so
// an input cannot make the loader build a mesh larger than the fuzzer's memory limit.
#include <soak/error.hpp>
#include <soak/scene.hpp>

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    // relative mesh paths resolve against the shipped scenes' folder
    soak::loadSceneFromString(text, "fuzz.json", SOAK_SOURCE_DIR "/scenes", {"solver.maxMemoryGB=0.05"});
  } catch (const soak::Error&) {
  }
  return 0;
}
