#pragma once
// Runs the `needle` binary as a user would and captures its exit code and stdout (tests only).
#include <catch2/catch.hpp>
#include <array>
#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace needle_test {

struct Result {
  int exit_code;
  std::string out;
};

// A shell command's exit code and stdout (add 2>&1 to read its stderr too).
inline Result shell(const std::string& command) {
  FILE* pipe = popen(command.c_str(), "r");
  REQUIRE(pipe);
  std::string out;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) out.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

// stdout only, or stdout and stderr together (to read error messages).
inline Result run(const std::string& args, bool with_stderr = false) {
  return shell(std::string(NEEDLE_BINARY) + " " + args + (with_stderr ? " 2>&1" : " 2>/dev/null"));
}

}  // namespace needle_test
