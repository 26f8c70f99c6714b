// Fuzz target: the sweep file reader (sweeps/sweep_plan.h) from a file, as `needle sweep` reads it before
// anything runs.
#include "fuzz/fuzz_input.h"
#include "sweeps/sweep_plan.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = needle_fuzz::input_file(data, size, ".json");
  return needle_fuzz::expect_result_or_input_error([&] { needle::read_sweep_file(path); });
}
