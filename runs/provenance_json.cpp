#include "runs/provenance_json.h"

#include "core/provenance.h"

namespace needle {

nlohmann::json provenance_json() {
  const Provenance& p = provenance();
  return {{"version", p.version}, {"commit", p.commit}, {"uncommitted_changes", p.dirty}, {"build_type", p.build_type}, {"blas", p.blas}, {"lapack", p.lapack}};
}

}  // namespace needle
