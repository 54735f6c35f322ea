// libFuzzer target: any bytes as a scene file. A SceneError is the loader refusing bad input,
// which is its job; anything else that escapes, a crash, a sanitizer report or a hang is a
// finding (libFuzzer reports the first three itself, and -timeout the last). Inputs that
// only ask for more memory than a machine has are skipped (affordable.hpp).

#include <cstddef>
#include <cstdint>
#include <string>

#include "affordable.hpp"
#include "cosserat/scene/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  if (!cosserat::fuzz::affordable(text, {})) return 0;
  try {
    cosserat::parse_scene(text, "fuzz.toml");
  } catch (const cosserat::SceneError&) {
  }
  return 0;
}
