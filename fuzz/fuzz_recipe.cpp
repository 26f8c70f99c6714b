// Fuzz target: the grinding recipe reader (runs/recipe_json.h) from a file, as `needle tip --recipe` reads it.
#include "fuzz/fuzz_input.h"
#include "runs/recipe_json.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = needle_fuzz::input_file(data, size, ".json");
  return needle_fuzz::expect_result_or_input_error([&] { needle::read_recipe_file(path); });
}
