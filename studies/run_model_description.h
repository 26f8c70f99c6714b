#pragma once
// One line that says which model a run ran (`needle paper`'s report and results.json "tissue"): the particles and the
// needle's cut always; then, each in its own words (its options' describe()), the tissue law and relaxation, the block,
// the slit, the crack, the lip, the contact, the needle model and contact law with the tissue's speed choices, the
// cutting pressure, the entry face, the drive and the groove start, each only where it is not the paper's model or the
// scene's default.
#include <string>

#include "runs/scene.h"

namespace needle {

// `particles`: the run's particle count (its summary.json). A stored run's scene is read by read_run_scene.
std::string describe_run_model(const Scene& scene, long particles);

}  // namespace needle
