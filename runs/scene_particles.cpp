#include "runs/scene_particles.h"

#include <fmt/format.h>

#include "core/input_error.h"

namespace needle {

ParticleSet scene_particles(const Scene& scene) {
  const TissueScene& t = scene.tissue;
  TissueBox box;
  const bool half = scene.needle.half_model;
  const double dy = t.offset_y_mm;
  box.min_mm = {t.entry_x_mm, -0.5 * t.size_mm.y() + dy, half ? 0.0 : -t.size_mm.z()};
  box.max_mm = {t.entry_x_mm + t.size_mm.x(), 0.5 * t.size_mm.y() + dy, t.size_mm.z()};
  if (!half) box.faces[4] = FaceCondition::fixed;
  LatticeOptions lattice;
  lattice.spacing_mm = t.spacing_mm;
  if (t.path_refinement > 1) {
    const double w = t.path_half_width_mm;
    NEEDLE_REQUIRE(w < 0.5 * t.size_mm.y() && w < t.size_mm.z(),
                   fmt::format("tissue: path_half_width_mm {} mm reaches the block's faces", w));
    lattice.region_of_interest =
        RegionOfInterest{{box.min_mm.x(), -w + dy, half ? 0.0 : -w}, {box.max_mm.x(), w + dy, w}, t.path_refinement, t.path_grading};
  }
  return make_particle_lattice(box, lattice);
}

}  // namespace needle
