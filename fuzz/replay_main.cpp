// A fuzz target without libFuzzer: runs LLVMFuzzerTestOneInput once on each file named (or each file in each
// folder named), so the inputs that once made a target fail are checked by every build's tests.
// Usage: fuzz_TARGET_replay [--accept] PATH... [--any PATH...]: the inputs after --accept must be taken by the
// reader (the shipped files), those after --any may be taken or refused in the project's words (the default).
// Exit status 1 when an input to accept is refused; a crash or another exception fails it as well.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  std::vector<std::pair<fs::path, bool>> files;  // path, must be accepted
  bool accept = false;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--accept" || arg == "--any") {
      accept = arg == "--accept";
      continue;
    }
    const fs::path p(arg);
    if (fs::is_directory(p)) {
      for (const fs::directory_entry& e : fs::directory_iterator(p))
        if (e.is_regular_file()) files.emplace_back(e.path(), accept);
    } else if (fs::is_regular_file(p)) {
      files.emplace_back(p, accept);
    } else {
      std::fprintf(stderr, "replay: no file or folder %s\n", arg.c_str());
      return 1;
    }
  }
  int refused = 0, failures = 0;
  for (const auto& [f, must_accept] : files) {
    std::ifstream in(f, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    if (needle_fuzz::last_refusal().empty()) continue;
    ++refused;
    if (must_accept) {
      std::fprintf(stderr, "replay: %s was refused: %s\n", f.string().c_str(), needle_fuzz::last_refusal().c_str());
      ++failures;
    }
  }
  std::printf("replayed %zu inputs: %d refused in the project's words, %d of them wrongly\n", files.size(), refused, failures);
  return failures ? 1 : 0;
}
