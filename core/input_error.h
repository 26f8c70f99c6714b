#pragma once
// One always-on check for bad user input: a clear message, caught once in apps/ and turned into a
// non-zero exit. Internal invariants use assert() instead.
#include <stdexcept>
#include <string>

namespace needle {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace needle

#define NEEDLE_REQUIRE(condition, message)                  \
  do {                                                      \
    if (!(condition)) throw ::needle::InputError(message);  \
  } while (false)
