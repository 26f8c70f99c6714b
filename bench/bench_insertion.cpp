// The coupled insertion: speed against error of the needle's time-stepping choices.
// A short SB insertion (16 mm modelled needle, T4 0.6 mm, 1.6 mm into a 2 x 3.2 x 1.2 mm half block of
// 0.4 mm particles, fixed sides), run with the plain full model (everything at the steel's stable step)
// and with subcycling at several coupling steps (contact_courant) and selective mass scaling. Prints
// the tip deflection, its error against the full model, the steps and the time of each.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fmt/format.h>

#include "geometry/grinding_recipe.h"
#include "mesher/needle_mesher.h"
#include "mesher/particle_lattice.h"
#include "solver/insertion/coupled_insertion.h"
#include "solver/needle/needle_dynamics.h"
#include "solver/separation/separation_models.h"

using namespace needle;
using Clock = std::chrono::steady_clock;

namespace {

struct Result {
  double deflection_mm = 0, seconds = 0, energy_error = 0;
  long steps = 0, needle_steps = 0;
};

Result insert(const TetMesh& mesh, bool subcycling, double contact_courant, double mass_scaling_dt_ms) {
  const auto start = Clock::now();
  const FeNeedle needle(mesh, NeedleMaterial{}, mass_scaling_dt_ms);
  const ContactSurface surface(needle.mesh());
  TissueBox box;
  box.min_mm = {0.0, -1.6, 0.0};
  box.max_mm = {2.0, 1.6, 1.2};
  box.faces = {FaceCondition::free, FaceCondition::free, FaceCondition::fixed, FaceCondition::fixed, FaceCondition::symmetry,
               FaceCondition::fixed};
  SpgTissue tissue(make_particle_lattice(box, LatticeOptions{}), TissueMaterial{}, SpgOptions{});
  InsertionProfile profile;
  profile.accel_time_ms = 0.02;
  profile.travel_mm = 1.6;
  NeedleDynamics dynamics(needle, driven_base_supports(needle.mesh(), profile), std::nullopt);
  CouplingOptions coupling;
  coupling.subcycling = subcycling;
  coupling.contact_courant = contact_courant;
  CoupledInsertion run(dynamics, tissue, surface, ContactOptions{}, make_separation_models(SeparationOptions{}, surface), coupling);
  const double end = profile.end_time_ms();
  while (run.time_ms() < end - 1e-12) run.step(end);
  const int tip = nearest_node(needle.mesh(), Eigen::Vector3d(0, -0.5, 0));
  Result r;
  r.deflection_mm = dynamics.positions_mm()(tip, 1) - needle.mesh().X(tip, 1);
  r.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  r.steps = run.steps();
  r.needle_steps = run.needle_steps();
  r.energy_error = run.energy().balance_error();
  return r;
}

}  // namespace

int main() {
  GrindingRecipe recipe = preset_recipe("SB");
  recipe.rod.length_mm = 16.0;
  recipe.groove->length_mm = 12.0;
  NeedleMeshOptions o;
  o.order = 1;
  o.size_mm = 0.6;
  o.high_order_optimize = false;
  const TetMesh mesh = mesh_needle(resolve_tip(recipe), true, o);
  fmt::print("Short SB insertion (16 mm needle, T4 0.6 mm, {} nodes; 1.6 mm into a 0.4 mm particle block)\n", mesh.num_nodes());
  const Result full = insert(mesh, false, 0.1, 0.0);
  fmt::print("{:<44} {:>14} {:>9} {:>9} {:>12} {:>8} {:>10}\n", "model", "deflection_mm", "error_%", "steps", "needle_steps", "time_s",
             "energy_err");
  auto row = [&](const std::string& name, const Result& r) {
    fmt::print("{:<44} {:>14.6f} {:>9.2f} {:>9} {:>12} {:>8.2f} {:>10.2e}\n", name, r.deflection_mm,
               100 * (r.deflection_mm - full.deflection_mm) / std::abs(full.deflection_mm), r.steps, r.needle_steps, r.seconds,
               r.energy_error);
  };
  row("full model (no subcycling, no mass scaling)", full);
  for (double courant : {0.5, 0.2, 0.1, 0.05}) row(fmt::format("subcycled, contact_courant {}", courant), insert(mesh, true, courant, 0.0));
  for (double ms : {6e-6, 1.2e-5}) row(fmt::format("subcycled 0.1 + mass scaling {} ms", ms), insert(mesh, true, 0.1, ms));
  return 0;
}
