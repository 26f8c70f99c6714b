// Bond failure: a notched bar pulled apart separates through the notch when the bonds' mean strain
// (plastic, or total effective) passes the threshold; broken bonds are counted, every particle and its mass survive.
#include <catch2/catch.hpp>
#include <cmath>
#include <numeric>

#include "solver/tissue/tissue_dynamics.h"
#include "tests/solver/solver_fixtures.h"

using namespace needle;

namespace {

// Union-find over the intact bonds.
std::vector<int> components(const SpgTissue& tissue) {
  std::vector<int> parent(static_cast<size_t>(tissue.particles().size()));
  std::iota(parent.begin(), parent.end(), 0);
  std::function<int(int)> find = [&](int i) { return parent[static_cast<size_t>(i)] == i ? i : parent[static_cast<size_t>(i)] = find(parent[static_cast<size_t>(i)]); };
  for (const Bond& b : tissue.bonds().bonds)
    if (!b.broken) parent[static_cast<size_t>(find(b.i))] = find(b.j);
  std::vector<int> root(parent.size());
  for (size_t i = 0; i < parent.size(); ++i) root[i] = find(static_cast<int>(i));
  return root;
}

}  // namespace

TEST_CASE("A notched bar pulled apart separates at the bond-failure strain", "[solver][failure][slow]") {
  // 12 x 3 x 2 mm bar, a notch of one particle plane removed over the lower half at x = 6.
  ParticleSet full = needle_test::free_box({0, -1.5, 0}, {12, 1.5, 2}, 0.5);
  std::vector<Eigen::Index> keep;
  for (Eigen::Index i = 0; i < full.x_mm.rows(); ++i)
    if (!(std::abs(full.x_mm(i, 0) - 6.0) < 1e-9 && full.x_mm(i, 1) < 0.1)) keep.push_back(i);
  ParticleSet set = full;
  set.x_mm = full.x_mm(keep, Eigen::all);
  set.volume_mm3 = full.volume_mm3(keep);
  set.spacing_mm = full.spacing_mm(keep);
  set.flags = full.flags(keep);

  TissueMaterial m;
  m.E_MPa = 0.1;  // yields at strain 0.49
  m.rate_law = RateLaw::off;
  SpgOptions options;
  // Plastic: 0.1 past yield. Effective: 0.6, past yield (0.49) too, so that the elastic and plastic
  // parts both count.
  options.bond_failure.measure = GENERATE(FailureMeasure::plastic_strain, FailureMeasure::effective_strain);
  const bool plastic_measure = options.bond_failure.measure == FailureMeasure::plastic_strain;
  options.bond_failure.strain = plastic_measure ? 0.1 : 0.6;
  SpgTissue tissue(set, m, options);
  TissueParticles& p = tissue.particles();
  const std::vector<double>& strain = plastic_measure ? p.plastic_strain : p.effective_strain;
  const double total_mass = std::accumulate(p.mass_g.begin(), p.mass_g.end(), 0.0);
  std::vector<std::int32_t> left, right;
  for (std::int64_t i = 0; i < p.size(); ++i) {
    if (p.reference_mm[static_cast<size_t>(i)].x() < 1e-9) left.push_back(static_cast<std::int32_t>(i));
    if (p.reference_mm[static_cast<size_t>(i)].x() > 12 - 1e-9) right.push_back(static_cast<std::int32_t>(i));
  }
  const double speed = 0.5;  // mm/ms each grip
  for (std::int64_t i = 0; i < p.size(); ++i)
    p.velocity_mm_per_ms[static_cast<size_t>(i)].x() = speed * (p.reference_mm[static_cast<size_t>(i)].x() - 6.0) / 6.0;
  TissueDynamics dynamics(tissue, {{left, 0, [=](double) { return -speed; }, {}}, {right, 0, [=](double) { return speed; }, {}}});
  double first_break_max_bond_strain = -1;
  bool separated = false;
  while (dynamics.time_ms() < 30.0 && !separated) {
    // The largest mean strain over intact bonds before the step: the first break must come
    // when it reaches the threshold, not before.
    double max_bond_strain = 0;
    for (const Bond& b : tissue.bonds().bonds)
      if (!b.broken) max_bond_strain = std::max(max_bond_strain, 0.5 * (strain[static_cast<size_t>(b.i)] + strain[static_cast<size_t>(b.j)]));
    const StepReport step = dynamics.step();
    if (step.bonds_broken_now > 0 && first_break_max_bond_strain < 0) first_break_max_bond_strain = max_bond_strain;
    if (tissue.bonds().broken_count > 0 && dynamics.steps() % 20 == 0) {
      const std::vector<int> root = components(tissue);
      separated = root[static_cast<size_t>(left.front())] != root[static_cast<size_t>(right.front())];
    }
  }
  INFO("broken bonds " << tissue.bonds().broken_count << " at t = " << dynamics.time_ms() << " ms");
  REQUIRE(separated);
  INFO("broken bonds " << tissue.bonds().broken_count << ", first break after the bond strain reached " << first_break_max_bond_strain);
  CHECK(first_break_max_bond_strain > 0.8 * options.bond_failure.strain);
  CHECK(first_break_max_bond_strain <= 1.2 * options.bond_failure.strain);
  // Every broken bond met the criterion (plastic strain only grows; the effective strain falls back by its
  // elastic part when the pieces unload, so it is checked at the first break above only). A bond between
  // detached crack-face particles only (SpgOptions::crack_face_min_volume_ratio) is dead, not failed.
  std::int64_t broken = 0, dead = 0;
  const std::vector<std::uint8_t>& valid = tissue.shape_functions().valid;
  for (const Bond& b : tissue.bonds().bonds) {
    if (!b.broken) continue;
    ++broken;
    if (!(b.entry_ij >= 0 && valid[static_cast<size_t>(b.i)]) && !(b.entry_ji >= 0 && valid[static_cast<size_t>(b.j)])) {
      ++dead;
      continue;
    }
    if (plastic_measure)
      CHECK(0.5 * (p.plastic_strain[static_cast<size_t>(b.i)] + p.plastic_strain[static_cast<size_t>(b.j)]) > options.bond_failure.strain);
  }
  CHECK(broken == tissue.bonds().broken_count);
  INFO(dead << " of the broken bonds are dead");
  // The crack runs through the notch plane: every broken bond straddles or touches x = 6 +- 1 mm.
  for (const Bond& b : tissue.bonds().bonds)
    if (b.broken) CHECK(std::abs(0.5 * (p.reference_mm[static_cast<size_t>(b.i)].x() + p.reference_mm[static_cast<size_t>(b.j)].x()) - 6.0) < 1.5);
  // Mass: all particles are still there, the two pieces together weigh what the bar did.
  const std::vector<int> root = components(tissue);
  double left_mass = 0, right_mass = 0;
  for (std::int64_t i = 0; i < p.size(); ++i)
    (root[static_cast<size_t>(i)] == root[static_cast<size_t>(left.front())] ? left_mass : right_mass) += p.mass_g[static_cast<size_t>(i)];
  CHECK(left_mass + right_mass == Approx(total_mass).epsilon(1e-14));
  CHECK(left_mass > 0.3 * total_mass);
  CHECK(right_mass > 0.3 * total_mass);
  for (const auto& x : p.position_mm) CHECK(x.allFinite());
}

TEST_CASE("Cut bonds separate their particles, squeezed crack-face particles detach, intact ones do not", "[solver][failure]") {
  // Cut every bond across the plane x = 1.1 of a 2 mm cube (cut_bonds, as the needle does), then squeeze
  // the whole block to a fifth of its volume. The particles with a cut bond are on a crack face: below
  // crack_face_min_volume_ratio they stop being integration points. The others are intact and stay.
  const ParticleSet set = needle_test::free_box({0, 0, 0}, {2, 2, 2}, 0.2);
  for (double threshold : {0.25, 0.1}) {
    SpgOptions options;
    options.crack_face_min_volume_ratio = threshold;
    SpgTissue tissue(set, TissueMaterial{}, options);
    std::vector<std::int64_t> across;
    std::vector<std::uint8_t> on_face(static_cast<size_t>(tissue.particles().size()), 0);
    for (size_t b = 0; b < tissue.bonds().bonds.size(); ++b) {
      const Bond& bond = tissue.bonds().bonds[b];
      const double xi = tissue.particles().position_mm[static_cast<size_t>(bond.i)].x(), xj = tissue.particles().position_mm[static_cast<size_t>(bond.j)].x();
      if ((xi - 1.1) * (xj - 1.1) < 0) {
        across.push_back(static_cast<std::int64_t>(b));
        on_face[static_cast<size_t>(bond.i)] = on_face[static_cast<size_t>(bond.j)] = 1;
      }
    }
    REQUIRE(!across.empty());
    CHECK(tissue.cut_bonds(across) == static_cast<std::int64_t>(across.size()));
    CHECK(tissue.bonds().cut_count == static_cast<std::int64_t>(across.size()));
    CHECK(tissue.bonds().broken_count == static_cast<std::int64_t>(across.size()));
    CHECK(tissue.cut_bonds(across) == 0);  // cut once
    // The two halves no longer share a bond.
    const std::vector<int> root = components(tissue);
    CHECK(root.front() != root.back());

    const double stretch = std::cbrt(0.2);  // det F = 0.2
    for (Vec3d& x : tissue.particles().position_mm) x *= stretch;
    const ForceReport report = tissue.compute_forces(0.0);
    const std::int64_t face = std::count(on_face.begin(), on_face.end(), std::uint8_t{1});
    INFO("threshold " << threshold << ": " << face << " crack-face particles of " << tissue.particles().size());
    if (threshold > 0.2) {
      CHECK(report.particles_detached_now == face);
      CHECK(tissue.valid_integration_points() == tissue.particles().size() - face);
    } else {
      CHECK(report.particles_detached_now == 0);
      CHECK(tissue.valid_integration_points() == tissue.particles().size());
    }
  }
}
