#pragma once
// A file the user names for reading (a scene, recipe, sweep, study, material or table): refused in the project's words
// when it is a folder (an ifstream opens a folder and fails on the first read with "basic_filebuf::underflow ... Is a
// directory"), anything but a regular file (a device such as /dev/zero would be read until memory runs out, a pipe
// with no writer would block), or larger than these small text files ever are. A path that does not exist passes: the
// reader says so in its own words.
#include <cstdint>
#include <filesystem>
#include <string>

#include "core/input_error.h"

namespace needle {

inline constexpr std::uintmax_t kMaxInputFileBytes = 64ull << 20;  // 64 MiB: the largest scene or sweep file is a few kB

inline void check_input_file(const std::string& path, const std::string& what, std::uintmax_t max_bytes = kMaxInputFileBytes) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) return;
  const std::string named = "cannot read the " + what + " '" + path + "': ";
  NEEDLE_REQUIRE(!fs::is_directory(status), named + "it is a folder, not a file");
  NEEDLE_REQUIRE(fs::is_regular_file(status), named + "it is not a regular file (a device, pipe or socket)");
  const std::uintmax_t size = fs::file_size(path, ec);
  NEEDLE_REQUIRE(ec || size <= max_bytes,
                 named + "it holds " + std::to_string(size) + " bytes, more than the " + std::to_string(max_bytes >> 20) + " MiB such a file may hold");
}

}  // namespace needle
