#include "core/provenance.h"

#include "needle_commit.h"

#ifndef NEEDLE_VERSION
#define NEEDLE_VERSION "unknown"
#endif
#ifndef NEEDLE_BUILD_TYPE
#define NEEDLE_BUILD_TYPE "unknown"
#endif

namespace needle {

const Provenance& provenance() {
  static const Provenance p{NEEDLE_VERSION, NEEDLE_COMMIT, NEEDLE_COMMIT_DIRTY != 0, NEEDLE_BUILD_TYPE};
  return p;
}

std::string provenance_line() {
  const Provenance& p = provenance();
  return "needle " + p.version + " (commit " + p.commit + (p.dirty ? ", with uncommitted changes" : "") + ", " + p.build_type + ")";
}

}  // namespace needle
