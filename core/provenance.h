#pragma once
// Which code made a result: the toolkit's version, the commit it was built from (and whether the work tree differed
// from it), the build type. `needle --version` prints it; every run folder's summary.json, a sweep's sweep.json, the
// paper report's results.json and a calibration record it (with the threads), so a stored result says which code
// made it.
#include <string>

namespace needle {

struct Provenance {
  std::string version;     // the project's version (CMakeLists.txt)
  std::string commit;      // 12 hex digits, or "unknown" (built outside a git work tree)
  bool dirty = false;      // the work tree had changes to tracked files when built
  std::string build_type;  // Release, Debug, ...
  // The BLAS and LAPACK this process loaded (resolved paths; "none" when not loaded). The build links Debian's
  // reference ones by path (solver/CMakeLists.txt), so they stay the same whichever BLAS the system's alternative selects.
  std::string blas, lapack;
};

const Provenance& provenance();

// "needle 0.1.0 (commit 0123456789ab, Release)", with ", with uncommitted changes" where dirty.
std::string provenance_line();

// "BLAS /usr/lib/.../blas/libblas.so.3.11.0, LAPACK /usr/lib/.../lapack/liblapack.so.3.11.0": the second line of --version.
std::string numerical_libraries_line();

// The resolved path of the loaded shared object whose file name starts with name_prefix (e.g. "libblas.so"), or "none".
std::string loaded_library(const std::string& name_prefix);

}  // namespace needle
