#include "mesher/gmsh_session.h"

#include <gmsh.h>

#include <cstdlib>
#include <stdexcept>
#include <thread>

namespace needle::detail {

GmshSession::GmshSession(const std::string& model_name, int threads) {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", std::getenv("NEEDLE_GMSH_LOG") ? 1 : 0);
  gmsh::option::setNumber("General.Verbosity", std::getenv("NEEDLE_GMSH_LOG") ? 5 : 1);
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  const int n = threads > 0 ? threads : (cores > 0 ? cores : 1);
  gmsh::option::setNumber("General.NumThreads", n);
  gmsh::option::setNumber("Mesh.MaxNumThreads1D", n);
  gmsh::option::setNumber("Mesh.MaxNumThreads2D", n);
  gmsh::option::setNumber("Mesh.MaxNumThreads3D", n);
  gmsh::model::add(model_name);
}

GmshSession::~GmshSession() { gmsh::finalize(); }

void gmsh_call(const std::string& context, const std::function<void()>& f) {
  try {
    f();
  } catch (const std::string& message) {
    throw std::runtime_error(context + ": gmsh: " + message);
  } catch (const char* message) {
    throw std::runtime_error(context + ": gmsh: " + std::string(message));
  }
}

}  // namespace needle::detail
