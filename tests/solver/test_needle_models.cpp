// The needle models behind NeedleModel (needle/needle_model.h), on their own: the registry by name; the FE
// needle (needle_dynamics.h) under a load proportional to its masses moves as a rigid body, momentum F t and
// position a t^2 / 2; the rigid needle (rigid_needle.h) follows its drive exactly and its drive's reaction
// balances the loads, with the energy account closed.
#include <catch2/catch.hpp>
#include <cmath>

#include "core/input_error.h"
#include "mesher/needle_mesher.h"
#include "solver/needle/needle_models.h"

using namespace needle;

namespace {

TetMesh rod(double length_mm = 4.0) {
  NeedleMeshOptions o;
  o.order = 1;
  o.size_mm = 0.4;
  o.high_order_optimize = false;
  return mesh_needle(plain_rod_tip(1.0, length_mm), true, o);
}

// A load of mass x a on every node (a uniform acceleration field), or a fixed force on one node.
struct FieldLoad : NeedleLoads {
  Eigen::VectorXd mass;
  Eigen::Vector3d a;
  int evaluations = 0;
  void needle_forces(const Eigen::MatrixX3d& x, const Eigen::MatrixX3d&, double, NodalForces& f) override {
    for (Eigen::Index i = 0; i < x.rows(); ++i) f.emplace_back(static_cast<int>(i), mass[i] * a);
    ++evaluations;
  }
};
struct PointLoad : NeedleLoads {
  int node = 0;
  Eigen::Vector3d force;
  void needle_forces(const Eigen::MatrixX3d&, const Eigen::MatrixX3d&, double, NodalForces& f) override { f.emplace_back(node, force); }
};

}  // namespace

TEST_CASE("Needle models are made by name, an unknown name lists the known ones", "[solver][needle]") {
  const FeNeedle needle(rod(), NeedleMaterial{}, 0.0);
  InsertionProfile profile;
  profile.accel_time_ms = 0.01;
  profile.travel_mm = 0.2;
  const NeedleModelInputs inputs{needle, driven_base_supports(needle.mesh(), profile), std::nullopt, {}};
  CHECK(make_needle_model("fe", inputs)->name() == "fe");
  CHECK(make_needle_model("rigid", inputs)->name() == "rigid");
  CHECK(std::isinf(make_needle_model("rigid", inputs)->time_step_ms()));
  CHECK(make_needle_model("fe", inputs)->time_step_ms() == Approx(0.9 * needle.stable_time_step_ms()));
  try {
    make_needle_model("beam", inputs);
    FAIL("an unknown model was made");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) == "needle.model: unknown needle model 'beam' (known: fe, implicit, rigid)");
  }
  // The traits the run code reads instead of names: only the FE needle runs alone (with its cannula), only the implicit
  // one takes the coupling step (and needs a contact load constant over it), only the explicit one is mass-scaled.
  CHECK(needle_model("fe").runs_alone);
  CHECK_FALSE(needle_model("implicit").runs_alone);
  CHECK_FALSE(needle_model("rigid").runs_alone);
  CHECK(needle_model("implicit").takes_coupling_step);
  CHECK_FALSE(needle_model("fe").takes_coupling_step);
  CHECK_FALSE(needle_model("rigid").takes_coupling_step);
  CHECK(needle_model("fe").mass_scaled);
  CHECK(needle_model("implicit").phrase == "the implicit linear needle");
}

TEST_CASE("A free FE needle under a mass-proportional load moves as a rigid body",
          "[solver][needle][gmsh]") {
  const FeNeedle needle(rod(), NeedleMaterial{}, 0.0);
  NeedleSupports free;  // no clamp, no drive, no symmetry plane: a free body
  free.profile.accel_time_ms = 0.01;
  free.profile.travel_mm = 1.0;
  std::unique_ptr<NeedleModel> model = make_needle_model("fe", {needle, free, std::nullopt, {}});
  FieldLoad load;
  load.mass = model->nodal_mass_g();
  load.a = Eigen::Vector3d(3.0, -1.0, 0.0);  // mm/ms^2, in the symmetry plane's directions
  model->apply_loads(load);
  const double end = 50 * model->time_step_ms();
  model->advance_to(end, load);
  const double t = model->time_ms(), mass = load.mass.sum();
  CHECK(t == Approx(end).epsilon(1e-12));
  CHECK(model->steps() >= 50);
  CHECK(load.evaluations == model->steps() + 1);  // once at the start, once per step
  CHECK((model->momentum() - mass * t * load.a).norm() < 1e-9 * mass * t * load.a.norm());
  const Eigen::MatrixX3d u = model->displacements_mm();
  double worst = 0;
  for (Eigen::Index i = 0; i < u.rows(); ++i) worst = std::max(worst, (u.row(i).transpose() - 0.5 * t * t * load.a).norm());
  INFO("worst displacement error " << worst << " mm of " << 0.5 * t * t * load.a.norm());
  CHECK(worst < 1e-6 * 0.5 * t * t * load.a.norm() + 1e-13);  // positions of ~4 mm round at 1e-15 mm
  const NeedleEnergy& e = model->energy();
  CHECK(e.strain_mJ < 1e-9 * e.kinetic_mJ);
  CHECK(e.external_work_mJ == Approx(e.kinetic_mJ).epsilon(1e-9));
  CHECK(e.balance_error() < 1e-9);
}

TEST_CASE("The rigid needle follows its drive exactly, and the drive's reaction balances the loads", "[solver][needle][gmsh]") {
  const FeNeedle needle(rod(), NeedleMaterial{}, 0.0);
  InsertionProfile profile;
  profile.accel_time_ms = 0.05;
  profile.speed_mm_per_ms = 4.0;
  profile.travel_mm = 1.0;
  std::unique_ptr<NeedleModel> model = make_needle_model("rigid", {needle, driven_base_supports(needle.mesh(), profile), std::nullopt, {}});
  PointLoad load;
  load.node = nearest_node(needle.mesh(), Eigen::Vector3d(0, -0.5, 0));
  load.force = Eigen::Vector3d(-0.02, 0.005, 0.0);  // N: the tissue pushing back on the tip
  model->apply_loads(load);
  const double end = profile.end_time_ms();
  for (int k = 1; k <= 20; ++k) {
    model->advance_to(k * end / 20, load);  // each call one step, whatever its length
    const Eigen::Vector3d d = profile.displacement_mm(model->time_ms()) * Eigen::Vector3d::UnitX();
    REQUIRE((model->displacements_mm().rowwise() - d.transpose()).cwiseAbs().maxCoeff() < 1e-12);
    REQUIRE((model->velocities_mm_per_ms().rowwise() - profile.velocity_mm_per_ms(model->time_ms()) * Eigen::RowVector3d::UnitX())
                .cwiseAbs()
                .maxCoeff() < 1e-12);
  }
  CHECK(model->steps() == 20);
  // At constant speed the drive holds the load: its reaction is minus the load.
  CHECK((model->drive_reaction_N() + load.force).norm() < 1e-12);
  // Its impulse is the momentum it gave the needle plus what the load took away.
  const double mass = model->nodal_mass_g().sum();
  const Eigen::Vector3d impulse_expected = mass * profile.velocity_mm_per_ms(end) * Eigen::Vector3d::UnitX() - end * load.force;
  CHECK((model->drive_impulse_N_ms() - impulse_expected).norm() < 1e-9 * impulse_expected.norm());
  CHECK(model->energy().balance_error() < 1e-12);
  CHECK(model->energy().external_work_mJ == Approx(load.force.x() * profile.displacement_mm(end)).epsilon(1e-9));
}
