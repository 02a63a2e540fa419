// libFuzzer target: scene JSON + --set overrides => load_scene_text. Input layout: leading
// lines "--set PATH=VALUE" are overrides, the rest is the scene text. Bad scenes must end in
// InputError, never a crash. Relative files resolve inside a folder that does not exist; inputs
// naming a device or kernel file are skipped, since reading /dev/zero never ends (a known
// limit: grammar and wind files are read whole, without a size cap).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "common/errors.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace treeanim;
  std::string text(reinterpret_cast<const char*>(data), size);
  for (const char* special : {"/dev", "/proc", "/sys"})
    if (text.find(special) != std::string::npos) return 0;
  std::vector<std::string> overrides;
  static const std::string kSet = "--set ";
  while (text.compare(0, kSet.size(), kSet) == 0) {
    const size_t end = text.find('\n');
    overrides.push_back(text.substr(kSet.size(), end == std::string::npos ? end : end - kSet.size()));
    text.erase(0, end == std::string::npos ? text.size() : end + 1);
  }
  try {
    load_scene_text(text, "fuzz.json", "/nonexistent-treeanim-fuzz", overrides);
  } catch (const InputError&) {
  }
  return 0;
}
