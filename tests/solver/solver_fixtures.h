#pragma once
// Small particle sets for the solver tests.
#include <random>

#include "mesher/particle_lattice.h"
#include "solver/tissue/tissue_material.h"

namespace needle_test {

// A free box lattice (all faces free).
inline needle::ParticleSet free_box(const Eigen::Vector3d& min_mm, const Eigen::Vector3d& max_mm, double spacing_mm) {
  needle::TissueBox box;
  box.min_mm = min_mm;
  box.max_mm = max_mm;
  box.faces.fill(needle::FaceCondition::free);
  needle::LatticeOptions options;
  options.spacing_mm = spacing_mm;
  return needle::make_particle_lattice(box, options);
}

// An elastic card for wave and vibration tests: E 1 MPa, the given nu, no rate effect (yield far away at small strain).
inline needle::TissueMaterial elastic_card(double nu) {
  needle::TissueMaterial m;
  m.E_MPa = 1.0;
  m.nu = nu;
  m.rate_law = needle::RateLaw::off;
  return m;
}

// The same lattice with every particle moved by up to +-fraction x spacing in each axis (fixed seed).
inline needle::ParticleSet jittered(needle::ParticleSet set, double fraction, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-fraction, fraction);
  for (Eigen::Index i = 0; i < set.x_mm.rows(); ++i)
    for (int k = 0; k < 3; ++k) set.x_mm(i, k) += u(rng) * set.spacing_mm[i];
  return set;
}

}  // namespace needle_test
