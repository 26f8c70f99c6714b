#pragma once
// A file the user names for reading: a folder in its place is refused in the project's words (an ifstream
// opens a folder and fails on the first read with "basic_filebuf::underflow ... Is a directory").
#include <filesystem>
#include <string>

#include "core/input_error.h"

namespace needle {

inline void refuse_folder_as_file(const std::string& path, const std::string& what) {
  NEEDLE_REQUIRE(!std::filesystem::is_directory(path), "cannot read the " + what + " '" + path + "': it is a folder, not a file");
}

}  // namespace needle
