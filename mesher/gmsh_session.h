#pragma once
// Internal to mesher/: gmsh is one global state; a session initialises it, starts an empty model and
// finalises it on every exit path. gmsh reports errors by throwing std::string; run() turns those
// into std::runtime_error with the context given.
#include <functional>
#include <string>

namespace needle::detail {

class GmshSession {
 public:
  explicit GmshSession(const std::string& model_name, int threads = 1);
  ~GmshSession();
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
};

// Runs f and converts gmsh's std::string exceptions into std::runtime_error("context: message").
void gmsh_call(const std::string& context, const std::function<void()>& f);

}  // namespace needle::detail
