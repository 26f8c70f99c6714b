// Fuzz target: the surface reader (geometry/mesh_io.h, read_surface through assimp) on STL files, binary or
// ASCII, as `needle tip --analyze` and `needle mesh --surface` read them.
#include "fuzz/fuzz_input.h"
#include "geometry/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = needle_fuzz::input_file(data, size, ".stl");
  return needle_fuzz::expect_result_or_input_error([&] { needle::read_surface(path); });
}
