// SPG tissue speed: particle-steps per second of the full explicit step (kinematics, stress update,
// force gather, stabilization, bond checks, integration) for 10k, 50k and 200k particles on 1 and 2
// threads, with the neighbour count. Anchor: LAMMPS MACHDYN total-Lagrangian SPH, 3-6e5 per core.
// Accuracy beside it: the uniaxial material test's error against the closed form at two spacings.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fmt/format.h>

#include "mesher/particle_lattice.h"
#include "solver/tissue/tissue_dynamics.h"
#include "core/parallel.h"
#include "solver/tissue/uniaxial_test.h"

using namespace needle;

int main(int argc, char** argv) {
  const int steps = argc > 1 ? std::atoi(argv[1]) : 20;
  fmt::print("SPG tissue step speed (paper card, spacing 0.4 mm, dilation 1.8, penalty stabilization, {} steps)\n", steps);
  fmt::print("{:>10} {:>12} {:>8} {:>14} {:>12} {:>16}\n", "particles", "neighbours", "threads", "setup s", "step ms", "particle-steps/s");
  for (const int target : {10000, 50000, 200000}) {
    // A block of the paper's 8 x 2 cross-section, long enough for the target count.
    const double h = 0.4;
    const double length = std::max(2.0, target / (21.0 * 6.0) * h);
    TissueBox box;
    box.min_mm = {0, -4, 0};
    box.max_mm = {std::round(length / h) * h, 4, 2};
    LatticeOptions lattice;
    lattice.spacing_mm = h;
    const ParticleSet set = make_particle_lattice(box, lattice);
    for (const int threads : {1, 2}) {
      const ThreadLimit limit(threads);
      const auto t0 = std::chrono::steady_clock::now();
      SpgTissue tissue(set, TissueMaterial{}, SpgOptions{});
      // A gentle compression wave from the entry face keeps every phase busy.
      std::vector<std::int32_t> face;
      for (std::int64_t i = 0; i < tissue.particles().size(); ++i)
        if (tissue.particles().reference_mm[static_cast<size_t>(i)].x() < 1e-9) face.push_back(static_cast<std::int32_t>(i));
      TissueDynamics dynamics(tissue, {{face, 0, [](double) { return 1.0; }, {}}});
      const auto t1 = std::chrono::steady_clock::now();
      for (int s = 0; s < steps; ++s) dynamics.step();
      const auto t2 = std::chrono::steady_clock::now();
      const double setup = std::chrono::duration<double>(t1 - t0).count();
      const double per_step = std::chrono::duration<double>(t2 - t1).count() / steps;
      fmt::print("{:>10} {:>12} {:>8} {:>14.2f} {:>12.2f} {:>16.3g}\n", set.num_particles(), tissue.shape_functions().entries(), threads,
                 setup, 1e3 * per_step, set.num_particles() / per_step);
    }
  }
  fmt::print("\nAccuracy beside speed: uniaxial test (E 0.1 MPa card, rate law off) to strain 1.5\n");
  fmt::print("{:>12} {:>10} {:>8} {:>10} {:>22}\n", "spacing mm", "particles", "steps", "seconds", "max error vs closed form");
  for (const double spacing : {0.75, 0.5}) {
    TissueMaterial card;
    card.E_MPa = 0.1;
    card.rate_law = RateLaw::off;
    UniaxialTestOptions options;
    options.spacing_mm = spacing;
    const UniaxialCurve curve = run_uniaxial_test(card, options);
    fmt::print("{:>12} {:>10} {:>8} {:>10.2f} {:>21.2f}%\n", spacing, curve.particles, curve.steps, curve.runtime_s,
               100 * curve.max_relative_error());
  }
  return 0;
}
