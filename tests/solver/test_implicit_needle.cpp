// The implicit needle (needle/implicit_needle.h) against independent computations: under a tip load ramped
// slowly and held, the static solution of the clamped needle (needle_statics.h, its own factorisation);
// under a tip load applied at once, the explicit FE needle's response over two periods (needle_dynamics.h,
// nonlinear, 2 000 times smaller steps); its energy account closed to rounding.
#include <catch2/catch.hpp>
#include <cmath>

#include "core/input_error.h"
#include "mesher/needle_mesher.h"
#include "solver/needle/implicit_needle.h"
#include "solver/needle/needle_models.h"
#include "solver/needle/needle_statics.h"

using namespace needle;

namespace {

constexpr double kLength = 8.0;  // a plain rod, x in [-8, 0], driven (held) at its base x = -8

TetMesh rod() {
  NeedleMeshOptions o;
  o.order = 1;
  o.size_mm = 0.3;
  o.high_order_optimize = false;
  return mesh_needle(plain_rod_tip(1.0, kLength), false, o);
}

// A drive that does not move (1e-12 mm over its travel): the base is held.
InsertionProfile held() {
  InsertionProfile p;
  p.accel_time_ms = 0;
  p.speed_mm_per_ms = 1e-12;
  p.travel_mm = 1e-12;
  return p;
}

std::vector<int> tip_nodes(const TetMesh& mesh) {
  std::vector<int> nodes;
  for (int i = 0; i < mesh.num_nodes(); ++i)
    if (mesh.X(i, 0) > -1e-9) nodes.push_back(i);
  return nodes;
}

// A downward load spread evenly over the tip's end face, ramped from 0 over ramp_ms (0: at once) and held.
struct TipLoad : NeedleLoads {
  std::vector<int> nodes;
  double total_N = 0, ramp_ms = 0;
  void needle_forces(const Eigen::MatrixX3d&, const Eigen::MatrixX3d&, double t, NodalForces& f) override {
    const double scale = ramp_ms > 0 ? std::min(1.0, t / ramp_ms) : 1.0;
    for (int n : nodes) f.emplace_back(n, Eigen::Vector3d(0, -scale * total_N / static_cast<double>(nodes.size()), 0));
  }
};

// 1/2 u.K u from the FE needle's own stiffness matrix (K annihilates the drive's rigid motion): what the model
// reports as its strain energy without multiplying by K.
double strain_energy_by_stiffness(const FeNeedle& fe, const ImplicitNeedle& model) {
  const Eigen::MatrixX3d u = model.displacements_mm();
  Eigen::VectorXd flat(3 * u.rows());
  for (Eigen::Index i = 0; i < u.rows(); ++i) flat.segment<3>(3 * i) = u.row(i).transpose();
  return 0.5 * flat.dot(fe.stiffness_matrix() * flat);
}

// The drive of the driven-base tests: 0.3 mm at 8 mm/ms after a 0.02 ms ramp, and the implicit step they take.
InsertionProfile short_drive() {
  InsertionProfile p;
  p.accel_time_ms = 0.02;
  p.speed_mm_per_ms = 8.0;
  p.travel_mm = 0.3;
  return p;
}

NeedleDynamicsOptions step_of(double implicit_step_ms) {
  NeedleDynamicsOptions o;
  o.implicit_step_ms = implicit_step_ms;
  return o;
}

double mean_tip_y(const NeedleModel& model, const std::vector<int>& nodes) {
  double sum = 0;
  for (int n : nodes) sum += model.positions_mm()(n, 1) - model.mesh().X(n, 1);
  return sum / static_cast<double>(nodes.size());
}

}  // namespace

TEST_CASE("Implicit needle: a slowly ramped tip load ends at the clamped needle's static deflection within 1 %",
          "[solver][needle][gmsh][slow]") {
  const FeNeedle fe(rod(), NeedleMaterial{}, 0.0);
  const NeedleSupports supports = driven_base_supports(fe.mesh(), held());
  const ClampedNeedle clamped(fe, supports.driven);
  const double period_ms = 1e3 / clamped.lowest_modes(1).front().frequency_hz;
  TipLoad load;
  load.nodes = tip_nodes(fe.mesh());
  load.total_N = 0.01;
  load.ramp_ms = 30 * period_ms;
  Eigen::MatrixX3d f = Eigen::MatrixX3d::Zero(fe.num_nodes(), 3);
  for (int n : load.nodes) f(n, 1) = -load.total_N / static_cast<double>(load.nodes.size());
  const Eigen::MatrixX3d u = clamped.solve(f);
  double expected = 0;
  for (int n : load.nodes) expected += u(n, 1) / static_cast<double>(load.nodes.size());

  NeedleDynamicsOptions options;
  options.implicit_step_ms = period_ms / 40;
  ImplicitNeedle needle(fe, supports, std::nullopt, options);
  needle.apply_loads(load);
  needle.advance_to(load.ramp_ms, load);
  // Held: the residual oscillation is about the static point; average it over one period.
  double mean = 0;
  int samples = 0;
  for (int k = 1; k <= 40; ++k) {
    needle.advance_to(load.ramp_ms + k * options.implicit_step_ms, load);
    mean += mean_tip_y(needle, load.nodes);
    ++samples;
  }
  mean /= samples;
  INFO("period " << period_ms << " ms; static " << expected << " mm, implicit " << mean << " mm");
  CHECK(expected < 0);
  CHECK(mean == Approx(expected).epsilon(0.01));
  CHECK(needle.factorizations() == 1);
}

TEST_CASE("Implicit needle: a tip load applied at once swings as the explicit FE needle does, within 1 % of the swing",
          "[solver][needle][gmsh][slow]") {
  const FeNeedle fe(rod(), NeedleMaterial{}, 0.0);
  const NeedleSupports supports = driven_base_supports(fe.mesh(), held());
  const double period_ms = 1e3 / ClampedNeedle(fe, supports.driven).lowest_modes(1).front().frequency_hz;
  TipLoad load;
  load.nodes = tip_nodes(fe.mesh());
  load.total_N = 0.01;
  NeedleDynamicsOptions options;
  options.implicit_step_ms = period_ms / 200;
  ImplicitNeedle implicit(fe, supports, std::nullopt, options);
  // The same with a longest step twice as long, asked for steps of half of it (it factors for those alone).
  NeedleDynamicsOptions coarse = options;
  coarse.implicit_step_ms = period_ms / 100;
  ImplicitNeedle shorter(fe, supports, std::nullopt, coarse);
  NeedleDynamics explicit_fe(fe, supports, std::nullopt, options);
  implicit.apply_loads(load);
  shorter.apply_loads(load);
  explicit_fe.apply_loads(load);
  double swing = 0, worst = 0, worst_shorter = 0;
  for (int k = 1; k <= 400; ++k) {
    const double t = k * period_ms / 200;  // two periods
    implicit.advance_to(t, load);
    shorter.advance_to(t, load);
    explicit_fe.advance_to(t, load);
    const double a = mean_tip_y(implicit, load.nodes), b = mean_tip_y(explicit_fe, load.nodes), c = mean_tip_y(shorter, load.nodes);
    swing = std::max(swing, std::abs(b));
    worst = std::max(worst, std::abs(a - b));
    worst_shorter = std::max(worst_shorter, std::abs(c - b));
  }
  INFO("swing " << swing << " mm, largest difference " << worst << " mm (h/2 of a longer h: " << worst_shorter
                << " mm); explicit steps " << explicit_fe.steps() << ", implicit " << implicit.steps());
  CHECK(swing > 0);
  CHECK(worst < 0.01 * swing);
  CHECK(worst_shorter < 0.01 * swing);
  CHECK(shorter.steps() == implicit.steps());
  CHECK(explicit_fe.steps() > 50 * implicit.steps());
  // Linear, undamped, loads held: the trapezoidal rule closes the account to rounding.
  INFO("implicit energy: kinetic " << implicit.energy().kinetic_mJ << " strain " << implicit.energy().strain_mJ << " external work "
                                   << implicit.energy().external_work_mJ);
  CHECK(implicit.energy().external_work_mJ > 0);
  CHECK(implicit.energy().strain_mJ == Approx(strain_energy_by_stiffness(fe, implicit)).epsilon(1e-9));
  CHECK(implicit.energy().balance_error() < 1e-6);
  CHECK(shorter.energy().balance_error() < 1e-6);
  CHECK(shorter.factorizations() == 1);
}

TEST_CASE("Implicit needle: driven at its base it moves with the drive and the drive's impulse is its momentum", "[solver][needle][gmsh]") {
  const FeNeedle fe(rod(), NeedleMaterial{}, 0.0);
  const InsertionProfile profile = short_drive();
  NeedleDynamicsOptions options = step_of(1e-3);
  ImplicitNeedle needle(fe, driven_base_supports(fe.mesh(), profile), std::nullopt, options);
  TipLoad none;
  needle.advance_to(profile.end_time_ms(), none);
  CHECK(needle.drive_displacement_mm().x() == Approx(0.3).epsilon(1e-12));
  // No load: the rod went with its base, compressed by its own inertia while the drive accelerated it
  // (rho a L^2 / 2E = 5.3e-4 mm at 400 mm/ms^2) and ringing axially since: its mean moved as the base did.
  const Eigen::MatrixX3d u = needle.displacements_mm();
  CHECK(std::abs(u.col(0).mean() - 0.3) < 1e-3);
  CHECK((u.col(0).array() - 0.3).abs().maxCoeff() < 2e-3);
  CHECK(u.col(1).cwiseAbs().maxCoeff() < 1e-4);
  // Momentum comes only through the drive; the drive's work is what the rod holds, within 1 %.
  CHECK((needle.momentum() - needle.drive_impulse_N_ms()).norm() < 1e-9 * needle.momentum().norm());
  CHECK(needle.energy().balance_error() < 0.01);
  // Clamped supports are refused: the model is built for a driven base.
  NeedleSupports clamped;
  clamped.clamped = {0};
  clamped.driven = {1};
  CHECK_THROWS_AS(ImplicitNeedle(fe, clamped, std::nullopt, options), InputError);
  options.implicit_step_ms = 0;
  CHECK_THROWS_AS(ImplicitNeedle(fe, driven_base_supports(fe.mesh(), profile), std::nullopt, options), InputError);
}

TEST_CASE("Implicit needle: a span taken ahead leaves the state as it was, and adopted it is the span advance_to takes, bit for bit",
          "[solver][needle][gmsh][ahead]") {
  const FeNeedle fe(rod(), NeedleMaterial{}, 0.0);
  const InsertionProfile profile = short_drive();
  NeedleDynamicsOptions options = step_of(1e-3);
  TipLoad load;
  load.nodes = tip_nodes(fe.mesh());
  load.total_N = 0.01;
  load.ramp_ms = 0.01;
  ImplicitNeedle plain(fe, driven_base_supports(fe.mesh(), profile), std::nullopt, options);
  ImplicitNeedle ahead(fe, driven_base_supports(fe.mesh(), profile), std::nullopt, options);
  CHECK(ahead.can_speculate());
  // Spans of 0.75 and 2.5 steps, the second a whole step and a remainder.
  const std::vector<double> ends = {0.75e-3, 3.25e-3, 4.0e-3, 6.5e-3};
  for (size_t k = 0; k < ends.size(); ++k) {
    const Eigen::MatrixX3d before = ahead.positions_mm();
    const long steps_before = ahead.steps();
    REQUIRE(ahead.speculate_advance(ends[k], load));
    // Nothing moved, and a span to another time is not adopted (and the kept one is dropped).
    CHECK(ahead.positions_mm() == before);
    CHECK(ahead.steps() == steps_before);
    CHECK(ahead.time_ms() == plain.time_ms());
    if (k == 2) {
      CHECK_FALSE(ahead.adopt_speculation(ends[k] + 1e-4));
      CHECK_FALSE(ahead.adopt_speculation(ends[k]));  // dropped
      ahead.advance_to(ends[k], load);
    } else {
      CHECK(ahead.adopt_speculation(ends[k]));
    }
    plain.advance_to(ends[k], load);
    CHECK(ahead.positions_mm() == plain.positions_mm());
    CHECK(ahead.velocities_mm_per_ms() == plain.velocities_mm_per_ms());
    CHECK(ahead.steps() == plain.steps());
    CHECK(ahead.time_ms() == plain.time_ms());
    CHECK(ahead.energy().strain_mJ == plain.energy().strain_mJ);
    CHECK(ahead.energy().drive_work_mJ == plain.energy().drive_work_mJ);
    CHECK(ahead.drive_impulse_N_ms() == plain.drive_impulse_N_ms());
  }
  // A speculation made before the state moved on is not adopted.
  REQUIRE(ahead.speculate_advance(8e-3, load));
  ahead.advance_to(7e-3, load);
  CHECK_FALSE(ahead.adopt_speculation(8e-3));
}

TEST_CASE("Implicit needle: stopped at once after its travel it rings with the kinetic energy it had, less its base's", "[solver][needle][gmsh]") {
  // The drive ends at full speed and then holds the base (no deceleration): the base stops at once, the rest of the rod
  // keeps its velocity and rings axially. Its energy after the stop is what it had less the held base's kinetic energy
  // (the stopping impulse's work, m_base v^2 / 2), and its account stays closed over the ringing; its momentum is the
  // drive's impulse throughout.
  const FeNeedle fe(rod(), NeedleMaterial{}, 0.0);
  InsertionProfile profile = short_drive();
  profile.hold_ms = 0.05;
  const NeedleDynamicsOptions options = step_of(1e-3);
  const NeedleSupports supports = driven_base_supports(fe.mesh(), profile);
  ImplicitNeedle needle(fe, supports, std::nullopt, options);
  TipLoad none;
  needle.advance_to(profile.travel_end_time_ms(), none);
  const double before_mJ = needle.energy().kinetic_mJ + needle.energy().strain_mJ;
  double base_mass_g = 0;
  for (const int i : supports.driven) base_mass_g += needle.nodal_mass_g()[i];
  const double base_mJ = 0.5 * base_mass_g * profile.speed_mm_per_ms * profile.speed_mm_per_ms;
  double worst_balance = 0;
  while (needle.time_ms() < profile.end_time_ms() - 1e-12) {
    needle.advance_to(std::min(profile.end_time_ms(), needle.time_ms() + 0.005), none);
    worst_balance = std::max(worst_balance, needle.energy().balance_error());
  }
  const double after_mJ = needle.energy().kinetic_mJ + needle.energy().strain_mJ;
  INFO("before " << before_mJ << " mJ, after " << after_mJ << " mJ, the base's " << base_mJ << " mJ");
  CHECK(after_mJ == Approx(before_mJ - base_mJ).epsilon(0.01));
  CHECK(needle.energy().kinetic_mJ < 0.9 * after_mJ);  // ringing: part of it is strain now
  CHECK(worst_balance < 0.01);
  CHECK((needle.momentum() - needle.drive_impulse_N_ms()).norm() < 1e-9 * std::max(1.0, needle.drive_impulse_N_ms().norm()));
  CHECK(needle.drive_displacement_mm().x() == Approx(0.3).epsilon(1e-12));
}

TEST_CASE("Implicit needle: a rod pressed against the cannula's bore is held there as the explicit FE needle's cannula holds it",
          "[solver][needle][gmsh][slow]") {
  // The base at x = -8 held, the cannula's front at x = -3 with 0.025 mm of clearance around the rod: a tip
  // load of 6 N, ramped over 10 periods and held, presses the rod's bottom line onto the bore at the front.
  const FeNeedle fe(rod(), NeedleMaterial{}, 0.0);
  const NeedleSupports supports = driven_base_supports(fe.mesh(), held());
  const double period_ms = 1e3 / ClampedNeedle(fe, supports.driven).lowest_modes(1).front().frequency_hz;
  CannulaOptions cannula;
  cannula.outer_diameter_mm = 1.1;
  cannula.wall_mm = 0.025;
  cannula.front_x_mm = -3.0;
  cannula.length_mm = 10.0;
  TipLoad load;
  load.nodes = tip_nodes(fe.mesh());
  load.total_N = 6.0;
  load.ramp_ms = 10 * period_ms;
  NeedleDynamicsOptions options;
  options.implicit_step_ms = period_ms / 40;
  ImplicitNeedle implicit(fe, supports, cannula, options);
  NeedleDynamics explicit_fe(fe, supports, cannula, options);
  implicit.apply_loads(load);
  explicit_fe.apply_loads(load);
  implicit.advance_to(load.ramp_ms, load);
  explicit_fe.advance_to(load.ramp_ms, load);
  double a = 0, b = 0, a_front = 0, b_front = 0;
  int implicit_nodes = 0, explicit_nodes = 0;
  const int front = nearest_node(fe.mesh(), Eigen::Vector3d(-3.0, -0.5, 0.0));
  for (int k = 1; k <= 40; ++k) {  // the mean over one period
    implicit.advance_to(load.ramp_ms + k * period_ms / 40, load);
    explicit_fe.advance_to(load.ramp_ms + k * period_ms / 40, load);
    implicit_nodes = std::max(implicit_nodes, implicit.cannula_contact().nodes_in_contact);
    explicit_nodes = std::max(explicit_nodes, explicit_fe.cannula_contact().nodes_in_contact);
    a += mean_tip_y(implicit, load.nodes) / 40;
    b += mean_tip_y(explicit_fe, load.nodes) / 40;
    a_front += implicit.displacements_mm()(front, 1) / 40;
    b_front += explicit_fe.displacements_mm()(front, 1) / 40;
  }
  INFO("tip: implicit " << a << " mm, explicit " << b << " mm; at the cannula's front: " << a_front << ", " << b_front
                        << " mm; cannula nodes " << implicit_nodes << " and " << explicit_nodes << ", the implicit's deepest "
                        << implicit.max_cannula_penetration_mm() << " mm");
  CHECK(implicit_nodes > 0);
  CHECK(explicit_nodes > 0);
  CHECK(a_front > -0.027);  // held at the bore, 0.025 mm below the rod's bottom line
  CHECK(a == Approx(b).epsilon(0.02));
  CHECK(a_front == Approx(b_front).epsilon(0.05));
  CHECK(implicit.max_cannula_penetration_mm() < 1e-3);
  // The strain energy from the step's own equation, with the cannula's springs in it, is 1/2 u.K u.
  CHECK(implicit.cannula_contact().nodes_in_contact > 0);
  CHECK(implicit.energy().strain_mJ > 0);
  CHECK(implicit.energy().strain_mJ == Approx(strain_energy_by_stiffness(fe, implicit)).epsilon(1e-9));
}
