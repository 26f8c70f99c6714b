// The FE needle in explicit dynamics: the paper's drive profile, the free needle pushed through the
// cannula, a needle whose drive is tilted into the cannula wall, and a free vibration against the
// modal analysis.
#include <catch2/catch.hpp>
#include <cmath>

#include "geometry/grinding_recipe.h"
#include "core/input_error.h"
#include "mesher/needle_mesher.h"
#include "solver/needle/needle_dynamics.h"
#include "solver/needle/needle_statics.h"
#include "solver/needle/needle_stiffness.h"
#include "core/solver_error.h"

using namespace needle;

namespace {

TetMesh rod_mesh(double length_mm, double size_mm, bool half, int order = 2) {
  NeedleMeshOptions o;
  o.order = order;
  o.size_mm = size_mm;
  o.high_order_optimize = false;
  return mesh_needle(plain_rod_tip(1.0, length_mm), half, o);
}

NeedleSupports driven_base(const FeNeedle& needle, bool half) {
  NeedleSupports s;
  s.driven = nodes_with_tag(needle.mesh(), "base");
  if (half) s.symmetry = nodes_with_tag(needle.mesh(), "symmetry");
  return s;
}

}  // namespace

TEST_CASE("The paper's drive profile: 0 to 8 m/s in 0.75 ms, then 8 m/s to 30 mm", "[solver][needle]") {
  const InsertionProfile p;
  CHECK(p.end_time_ms() == Approx(0.75 + 27.0 / 8.0));
  CHECK(p.displacement_mm(0.75) == Approx(3.0));
  CHECK(p.displacement_mm(p.end_time_ms()) == Approx(30.0));
  CHECK(p.velocity_mm_per_ms(0.375) == Approx(4.0));
  // The displacement is the integral of the velocity (midpoint rule, 10^5 intervals).
  const int n = 100000;
  double integral = 0;
  for (int i = 0; i < n; ++i) integral += p.velocity_mm_per_ms((i + 0.5) * p.end_time_ms() / n) * p.end_time_ms() / n;
  CHECK(integral == Approx(30.0).epsilon(1e-6));
  InsertionProfile bad;
  bad.travel_mm = 1.0;  // shorter than the 3 mm ramp
  CHECK_THROWS_AS(bad.validate(), InputError);
  bad = InsertionProfile{};
  bad.speed_mm_per_ms = -8;
  CHECK_THROWS_AS(bad.validate(), InputError);
  bad = InsertionProfile{};
  bad.hold_ms = -0.1;
  CHECK_THROWS_AS(bad.validate(), InputError);
}

TEST_CASE("A hold after the travel: the base stops at the travel's end and stays there", "[solver][needle]") {
  InsertionProfile p;
  p.hold_ms = 0.5;
  p.validate();
  const double travel_end = 0.75 + 27.0 / 8.0;
  CHECK(p.travel_end_time_ms() == Approx(travel_end));
  CHECK(p.end_time_ms() == Approx(travel_end + 0.5));
  CHECK(p.velocity_mm_per_ms(travel_end) == Approx(8.0));
  CHECK(p.velocity_mm_per_ms(travel_end + 1e-9) == 0.0);
  CHECK(p.displacement_mm(travel_end + 0.25) == Approx(30.0));
  CHECK(p.displacement_mm(p.end_time_ms()) == Approx(30.0));
}

TEST_CASE("A deceleration ramp: the base comes to rest exactly at the travel, its velocity continuous", "[solver][needle]") {
  InsertionProfile p;
  p.decel_time_ms = 0.25;  // 1 mm of the 30 at 8 m/s
  p.hold_ms = 0.1;
  p.validate();
  const double cruise_end = 0.75 + (30.0 - 3.0 - 1.0) / 8.0;
  CHECK(p.cruise_end_time_ms() == Approx(cruise_end));
  CHECK(p.travel_end_time_ms() == Approx(cruise_end + 0.25));
  CHECK(p.end_time_ms() == Approx(cruise_end + 0.35));
  CHECK(p.velocity_mm_per_ms(cruise_end) == Approx(8.0));
  CHECK(p.velocity_mm_per_ms(cruise_end + 0.125) == Approx(4.0));
  CHECK(p.velocity_mm_per_ms(cruise_end + 0.25 - 1e-9) == Approx(0.0).margin(1e-6));
  CHECK(p.displacement_mm(cruise_end) == Approx(29.0));
  CHECK(p.displacement_mm(cruise_end + 0.125) == Approx(29.0 + 0.75));  // 8 * 0.125 - 8 * 0.125^2 / (2 * 0.25)
  CHECK(p.displacement_mm(p.end_time_ms()) == Approx(30.0));
  // The displacement is the integral of the velocity through all three phases and the hold.
  const int n = 200000;
  double integral = 0;
  for (int i = 0; i < n; ++i) integral += p.velocity_mm_per_ms((i + 0.5) * p.end_time_ms() / n) * p.end_time_ms() / n;
  CHECK(integral == Approx(30.0).epsilon(1e-6));
  InsertionProfile bad = p;
  bad.travel_mm = 3.5;  // shorter than the 3 + 1 mm of the two ramps
  CHECK_THROWS_AS(bad.validate(), InputError);
  bad = p;
  bad.decel_time_ms = -1;
  CHECK_THROWS_AS(bad.validate(), InputError);
}

TEST_CASE("Mirroring a half mesh gives an exactly symmetric, conforming full mesh", "[mesher][needle]") {
  const TetMesh half = rod_mesh(5.0, 0.5, true, 1);
  const TetMesh full = mirrored_union(half, 2);
  CHECK(full.num_tets() == 2 * half.num_tets());
  CHECK(full.tag_index("symmetry") >= 0);  // the tag name stays; no face carries it
  for (int f = 0; f < full.num_boundary_faces(); ++f) CHECK(full.tag_names[static_cast<size_t>(full.boundary_tag[f])] != "symmetry");
  // Conforming: the FE model builds (no inverted element) and its volume is twice the half's.
  const FeNeedle h(half, NeedleMaterial{}), m(full, NeedleMaterial{});
  CHECK(m.volume_mm3() == Approx(2 * h.volume_mm3()).epsilon(1e-12));
  // Every interior face is shared by two tets: a rigid motion still gives zero force, and a uniform
  // stretch gives a force only on the boundary (a crack along the plane would show forces there).
  Eigen::MatrixX3d x = full.X, f;
  x.col(0) *= 1.001;
  m.internal_forces(x, f);
  std::vector<char> on_boundary(static_cast<size_t>(full.num_nodes()), 0);
  for (int b = 0; b < full.num_boundary_faces(); ++b)
    for (int k = 0; k < 3; ++k) on_boundary[static_cast<size_t>(full.boundary_faces(b, k))] = 1;
  double interior = 0;
  for (int i = 0; i < full.num_nodes(); ++i)
    if (!on_boundary[static_cast<size_t>(i)]) interior = std::max(interior, f.row(i).norm());
  CHECK(interior < 1e-9 * f.cwiseAbs().maxCoeff());
}

TEST_CASE("A free rod pushed through the cannula by the paper's profile ends undeflected, energy balanced", "[solver][needle][gmsh][slow]") {
  // A full rod mirrored from a half (so exactly symmetric in y: any deflection would be spurious),
  // T4, selective mass scaling to a 4e-5 ms step (adds ~15 % mass in the few smallest tets; the
  // deflection and the balance do not depend on it).
  const TetMesh half = rod_mesh(40.0, 0.5, true, 1);
  TetMesh turned = half;  // z >= 0 half turned to y >= 0, then mirrored in y
  turned.X.col(1) = half.X.col(2);
  turned.X.col(2) = -half.X.col(1);
  const FeNeedle needle(mirrored_union(turned, 1), NeedleMaterial{}, 4e-5);
  NeedleSupports supports = driven_base(needle, false);
  const CannulaOptions cannula;  // paper: OD 1.27, wall 0.05, front at the entry face x = 0, 40 mm long
  NeedleDynamics run(needle, supports, cannula);
  const int tip = nearest_node(needle.mesh(), Eigen::Vector3d::Zero());
  double max_deflection = 0;
  int contacts = 0;
  while (run.time_ms() < supports.profile.end_time_ms() - 1e-12) {
    run.step(supports.profile.end_time_ms());
    max_deflection = std::max(max_deflection, std::abs(run.displacements_mm()(tip, 1)));
    contacts += run.cannula_contact().nodes_in_contact;
  }
  INFO("steps " << run.steps() << " dt " << run.time_step_ms() << " max |deflection| " << max_deflection << " balance "
                << run.energy().balance_error() << " KE " << run.energy().kinetic_mJ << " W " << run.energy().drive_work_mJ);
  CHECK(run.displacements_mm()(tip, 0) == Approx(30.0).epsilon(1e-3));
  CHECK(std::abs(run.displacements_mm()(tip, 1)) < 1e-6);
  CHECK(max_deflection < 1e-6);
  CHECK(contacts == 0);  // the 0.085 mm radial gap is never closed
  CHECK(run.energy().balance_error() < 0.005);
  // The drive's work is about the kinetic energy of the whole (scaled) mass at 8 m/s; the axial
  // vibration the ramp's start leaves in the rod makes up the difference.
  CHECK(run.energy().drive_work_mJ == Approx(0.5 * needle.nodal_mass_g().sum() * 64.0).epsilon(0.02));
}

TEST_CASE("A needle driven at an angle into the cannula wall is held by it", "[solver][needle][gmsh][slow]") {
  const FeNeedle needle(rod_mesh(20.0, 0.5, true, 1), NeedleMaterial{}, 4e-5);
  NeedleSupports supports = driven_base(needle, true);
  supports.direction = Eigen::Vector3d(std::cos(2.0 * M_PI / 180), std::sin(2.0 * M_PI / 180), 0.0);  // 2 degrees up
  supports.profile.travel_mm = 4.0;  // the base rises 0.14 mm, more than the 0.085 mm gap
  CannulaOptions cannula;
  cannula.length_mm = 12.0;  // the base stays behind the cannula, free to rise
  NeedleDynamics run(needle, supports, cannula);
  int max_contacts = 0;
  while (run.time_ms() < supports.profile.end_time_ms() - 1e-12) {
    run.step(supports.profile.end_time_ms());
    max_contacts = std::max(max_contacts, run.cannula_contact().nodes_in_contact);
  }
  const Eigen::MatrixX3d& x = run.positions_mm();
  const double r_in = cannula.inner_radius_mm();
  double worst = -1;
  for (int i = 0; i < x.rows(); ++i)
    if (x(i, 0) > -cannula.length_mm && x(i, 0) < 0) worst = std::max(worst, std::hypot(x(i, 1), x(i, 2)) - r_in);
  const double rise = supports.profile.travel_mm * std::sin(2.0 * M_PI / 180);
  INFO("rise " << rise << " worst radial excess " << worst << " contacts " << max_contacts << " balance "
               << run.energy().balance_error() << " cannula work " << run.energy().cannula_work_mJ);
  CHECK(max_contacts > 0);
  CHECK(worst < 2e-3);         // held within the bore (penalty penetration is microns)
  CHECK(rise - 0.085 > 0.04);  // while a free needle would have passed the wall by 0.05 mm
  CHECK(run.energy().cannula_work_mJ < 0);  // friction and the held bend take energy out
  CHECK(run.energy().balance_error() < 0.005);
}

TEST_CASE("A released cantilever vibrates at the frequency of the modal analysis", "[solver][needle][gmsh][slow]") {
  // Same mesh and (scaled) masses for both, so the explicit integration is checked against the
  // eigen-solution of the same discrete system.
  const FeNeedle needle(rod_mesh(20.0, 0.4, false, 1), NeedleMaterial{}, 1e-4);
  const std::vector<int> base = nodes_with_tag(needle.mesh(), "base");
  const ClampedNeedle statics(needle, base);
  const double f1_hz = statics.lowest_modes(2)[0].frequency_hz;
  Eigen::MatrixX3d load = Eigen::MatrixX3d::Zero(needle.num_nodes(), 3);
  load.col(1) = facet_load_weights(needle.mesh(), {"end"});
  const Eigen::MatrixX3d u0 = 1e-3 * statics.solve(load);  // small: linear regime
  NeedleSupports supports;
  supports.clamped = base;
  NeedleDynamics run(needle, supports, std::nullopt);
  run.set_initial_state(needle.mesh().X + u0, Eigen::MatrixX3d::Zero(needle.num_nodes(), 3));
  const int tip = nearest_node(needle.mesh(), Eigen::Vector3d::Zero());
  // Downward zero crossings of the tip's y displacement, interpolated within the step.
  std::vector<double> crossings;
  double previous = u0(tip, 1);
  const double periods = 4.0, end = periods * 1000.0 / f1_hz;
  while (run.time_ms() < end) {
    run.step(end);
    const double y = run.displacements_mm()(tip, 1);
    if (previous > 0 && y <= 0) crossings.push_back(run.time_ms() - run.time_step_ms() * y / (y - previous));
    previous = y;
  }
  REQUIRE(crossings.size() >= 3);
  const double period_ms = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  INFO("modal " << f1_hz << " Hz, explicit " << 1000.0 / period_ms << " Hz, steps " << run.steps() << ", balance "
                << run.energy().balance_error());
  CHECK(1000.0 / period_ms == Approx(f1_hz).epsilon(0.01));
  // Free vibration: energy is conserved (no work in or out).
  CHECK(std::abs(run.energy().kinetic_mJ + run.energy().strain_mJ - run.energy().initial_mJ) < 1e-3 * run.energy().initial_mJ);
}
