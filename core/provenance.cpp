#include "core/provenance.h"

#include <link.h>

#include <filesystem>
#include <system_error>

#include "needle_commit.h"

#ifndef NEEDLE_VERSION
#define NEEDLE_VERSION "unknown"
#endif
#ifndef NEEDLE_BUILD_TYPE
#define NEEDLE_BUILD_TYPE "unknown"
#endif

namespace needle {

std::string loaded_library(const std::string& name_prefix) {
  struct Search {
    const std::string* prefix;
    std::string path;
  } search{&name_prefix, ""};
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void* data) {
        auto* s = static_cast<Search*>(data);
        if (!info->dlpi_name || !*info->dlpi_name) return 0;
        const std::string path = info->dlpi_name;
        const std::string file = std::filesystem::path(path).filename().string();
        if (file.rfind(*s->prefix, 0) != 0) return 0;
        s->path = path;
        return 1;
      },
      &search);
  if (search.path.empty()) return "none";
  std::error_code error;
  const std::filesystem::path resolved = std::filesystem::canonical(search.path, error);
  return error ? search.path : resolved.string();
}

const Provenance& provenance() {
  static const Provenance p{NEEDLE_VERSION, NEEDLE_COMMIT, NEEDLE_COMMIT_DIRTY != 0, NEEDLE_BUILD_TYPE,
                            loaded_library("libblas.so"), loaded_library("liblapack.so")};
  return p;
}

std::string numerical_libraries_line() {
  const Provenance& p = provenance();
  return "BLAS " + p.blas + ", LAPACK " + p.lapack;
}

std::string provenance_line() {
  const Provenance& p = provenance();
  return "needle " + p.version + " (commit " + p.commit + (p.dirty ? ", with uncommitted changes" : "") + ", " + p.build_type + ")";
}

}  // namespace needle
