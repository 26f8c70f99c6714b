#pragma once
// What every fuzz target shares: the input as a file where the reader takes a path, and the rule a target
// checks. A reader given any bytes either returns or throws InputError (the one-line error a user sees with
// exit 2); a crash, a sanitizer's report, a hang or any other exception is a finding.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "core/input_error.h"

namespace needle_fuzz {

// The input written to a file named with the given extension in the temporary folder (one per process).
inline std::string input_file(const std::uint8_t* data, std::size_t size, const std::string& extension) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("needle_fuzz_" + std::to_string(::getpid()) + extension);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path.string();
}

// The last input's refusal (InputError's words), empty when the reader took it: replay_main.cpp checks that the
// shipped files are taken.
inline std::string& last_refusal() {
  static std::string words;
  return words;
}

// Runs read on the input; InputError is the reader refusing it, which is what it should do.
template <class Read>
int expect_result_or_input_error(const Read& read) {
  last_refusal().clear();
  try {
    read();
  } catch (const needle::InputError& e) {
    last_refusal() = e.what();
    if (last_refusal().empty()) last_refusal() = "(an InputError without words)";
  }
  return 0;
}

}  // namespace needle_fuzz
