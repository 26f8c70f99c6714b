#pragma once
// The tissue particles a scene describes (docs/scenes.md, `tissue`): the block from the entry face, centred on the
// path in y (shifted by offset_y_mm: the lattice's phase across the path), from the symmetry plane in z for a half
// model, finer within path_half_width_mm of the path. The whole set moves with offset_y_mm and entry_x_mm, band and
// all, so that each is a phase of the lattice against the needle's path.
#include "mesher/particle_lattice.h"
#include "runs/scene.h"

namespace needle {

// InputError where the band around the path reaches the block's faces.
ParticleSet scene_particles(const Scene& scene);

}  // namespace needle
