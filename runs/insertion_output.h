#pragma once
// A coupled run's files as it goes: history.csv (one row a record: the deflection, forces, energies and each separation
// model's columns), facet_forces.csv (the contact on each tagged facet) and the ParaView frames (needle_NNNN.vtu,
// tissue_NNNN.vtp in binary, needle.pvd and tissue.pvd).
#include <fstream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "runs/run_folder.h"
#include "solver/contact/contact_surface.h"
#include "solver/insertion/coupled_insertion.h"
#include "solver/insertion/groove_fill.h"
#include "solver/separation/separation_model.h"

namespace needle {

class InsertionOutput {
 public:
  InsertionOutput(const RunFolder& folder, const ContactSurface& surface, const std::vector<std::unique_ptr<SeparationModel>>& separations);
  // One row of history.csv and facet_forces.csv; tip: the node whose displacement is the tip's.
  void record(const CoupledInsertion& run, int tip, const GrooveFill& groove);
  // One ParaView frame of the needle and the particles.
  void frame(const CoupledInsertion& run);
  // Closes the tables and writes the .pvd collections.
  void finish();

 private:
  const RunFolder& folder_;
  const ContactSurface& surface_;
  std::ofstream history_, facets_;
  std::vector<std::pair<double, std::string>> needle_frames_, tissue_frames_;
};

}  // namespace needle
