// Fuzz target: the scene reader (runs/scene.h, parse_scene) and, for a scene it accepts, writing it back and
// reading that again (the stored scene.json of every run folder must read back as the same scene).
#include "fuzz/fuzz_input.h"
#include "runs/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return needle_fuzz::expect_result_or_input_error([&] {
    const needle::Scene scene = needle::parse_scene(std::string(reinterpret_cast<const char*>(data), size), "fuzz.json");
    const std::string stored = needle::scene_to_json(scene).dump();
    const needle::Scene again = needle::parse_scene(stored, "stored scene.json");
    if (needle::scene_to_json(again).dump() != stored) __builtin_trap();  // a scene that does not read back as written
  });
}
