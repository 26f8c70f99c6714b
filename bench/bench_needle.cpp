// Needle FE: speed against error.
//  1. Tip compliance of a plain rod (closed form) and of LMB (Euler-Bernoulli with the exact
//     sections), T4 and T10 at several sizes: the mesh convergence, with the time of each solve.
//  2. Explicit steps per second on the paper's 0.2 mm T10 half mesh (SB and LMB), with the stable
//     step, the run length the paper's 4.125 ms profile would take, and what selective mass scaling
//     buys (step, added mass).
//  3. The implicit needle's step solve on the run defaults' 0.4 mm T10 half mesh of SB: the default model's longest
//     serial path (about 5 ms a needle step, a third of SB's wall time: docs/notebook/multirate.md), by the
//     factorisation the model uses and by others, with each one's difference from it (a cheaper one changes the
//     rounding, so results would move within their scatter and E would be recalibrated).
#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fmt/format.h>

#include "geometry/exact_measures.h"
#include "geometry/grinding_recipe.h"
#include "mesher/needle_mesher.h"
#include "solver/needle/beam_reference.h"
#include "solver/needle/implicit_needle.h"
#include "solver/needle/needle_dynamics.h"
#include "solver/needle/needle_stiffness.h"
#include "core/parallel.h"

using namespace needle;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

TetMesh mesh_of(const TipGeometry& tip, bool half, int order, double size) {
  NeedleMeshOptions o;
  o.order = order;
  o.size_mm = size;
  o.high_order_optimize = false;
  return mesh_needle(tip, half, o);
}

void convergence(const std::string& label, const TipGeometry& tip, const std::vector<std::string>& load_faces, double reference_y) {
  fmt::print("\n{}: tip compliance in y, clamped {} mm behind A (reference {:.5g} mm/N)\n", label, -tip.base_x_mm, reference_y);
  fmt::print("{:>6} {:>6} {:>9} {:>9} {:>14} {:>10} {:>10}\n", "order", "size", "elements", "dofs", "compliance", "error %", "solve s");
  for (int order : {1, 2})
    for (double size : {0.4, 0.3, 0.2}) {
      const auto t0 = Clock::now();
      const FeNeedle needle(mesh_of(tip, false, order, size), NeedleMaterial{});
      const StiffnessResult r = analyse_stiffness(needle, tip.tip_point, load_faces);
      fmt::print("{:>6} {:>6.2f} {:>9} {:>9} {:>14.5g} {:>+10.2f} {:>10.2f}\n", order == 2 ? "T10" : "T4", size,
                 needle.num_elements(), r.free_dofs, r.compliance_y_mm_per_N, 100 * (r.compliance_y_mm_per_N / reference_y - 1), since(t0));
    }
}

}  // namespace

int main(int argc, char** argv) {
  const int steps = argc > 1 ? std::atoi(argv[1]) : 300;
  const NeedleMaterial steel;
  // 1. Convergence.
  const TipGeometry rod = plain_rod_tip(1.0, 30.0);
  convergence("plain rod, closed form L^3 / 3EI", rod, {"end"}, std::pow(30.0, 3) / (3 * steel.youngs_modulus_MPa * M_PI / 64));
  GrindingRecipe lmb_recipe = preset_recipe("LMB");
  lmb_recipe.rod.length_mm = 40.0;
  const TipGeometry lmb = resolve_tip(lmb_recipe);
  std::vector<std::string> lmb_faces;
  for (const auto& f : lmb.facets) lmb_faces.push_back(f.name);
  {
    // The load's resultant x, from a mesh, for the beam reference.
    const FeNeedle probe(mesh_of(lmb, false, 2, 0.3), steel);
    const Eigen::VectorXd w = facet_load_weights(probe.mesh(), lmb_faces);
    const double load_x = w.dot(probe.mesh().X.col(0));
    ExactOptions exact;
    exact.circle_vertices = 4096;
    const double reference = cantilever_compliance_mm_per_N([&](double x) { return exact_section(lmb, x, exact).I_z_mm4; },
                                                            steel.youngs_modulus_MPa, lmb.base_x_mm, load_x, 0.0,
                                                            {lmb.groove->back_x_mm, lmb.groove->front_x_mm});
    convergence("LMB, Euler-Bernoulli with the exact grooved sections", lmb, lmb_faces, reference);
  }

  // 2. Explicit speed on the paper's mesh.
  fmt::print("\nExplicit needle steps on the paper's 0.2 mm T10 half mesh ({} steps, driven base, cannula)\n", steps);
  fmt::print("{:>5} {:>9} {:>8} {:>8} {:>12} {:>11} {:>12} {:>14} {:>14}\n", "tip", "elements", "nodes", "threads", "dt ms",
             "steps/s", "element-steps/s", "4.125 ms run", "");
  for (const std::string preset : {"SB", "LMB"}) {
    const TipGeometry tip = resolve_tip(preset_recipe(preset));
    const TetMesh mesh = mesh_of(tip, true, 2, 0.2);
    const FeNeedle needle(mesh, steel);
    for (int threads : {1, 2}) {
      const ThreadLimit limit(threads);
      NeedleSupports supports;
      supports.driven = nodes_with_tag(needle.mesh(), "base");
      supports.symmetry = nodes_with_tag(needle.mesh(), "symmetry");
      NeedleDynamics run(needle, supports, CannulaOptions{});
      const auto t0 = Clock::now();
      for (int i = 0; i < steps; ++i) run.step();
      const double rate = steps / since(t0);
      const double run_steps = supports.profile.end_time_ms() / run.time_step_ms();
      fmt::print("{:>5} {:>9} {:>8} {:>8} {:>12.4g} {:>11.0f} {:>12.3g} {:>12.0f} s {:>14}\n", preset, needle.num_elements(),
                 needle.num_nodes(), threads, run.time_step_ms(), rate, rate * needle.num_elements(), run_steps / rate, "");
    }
    fmt::print("  selective mass scaling on {}: target step -> added mass, steps for 4.125 ms\n", preset);
    for (double target : {2e-6, 5e-6, 1e-5, 2e-5}) {
      const FeNeedle scaled(mesh, steel, target);
      fmt::print("    {:8.0e} ms -> {:7.2f} % in {:6} elements, {:8.0f} steps\n", target, 100 * scaled.added_mass_g() / scaled.physical_mass_g(),
                 scaled.mass_scaled_elements(), 4.125 / (0.9 * scaled.stable_time_step_ms()));
    }
  }

  // 3. The implicit needle's solve.
  {
    const TipGeometry tip = resolve_tip(preset_recipe("SB"));
    const FeNeedle needle(mesh_of(tip, true, 2, 0.4), steel);
    // A = K + 4/h^2 M on the free components, h the paper scene's implicit step (0.002 ms): the model's own matrix.
    const double h = 0.002;
    NeedleDynamicsOptions options;
    options.implicit_step_ms = h;
    const ImplicitNeedle model(needle, driven_base_supports(needle.mesh(), InsertionProfile{}), std::nullopt, options);
    const Eigen::SparseMatrix<double> A = model.step_matrix(h);
    const Eigen::Index free = A.rows();
    const Eigen::VectorXd rhs = Eigen::VectorXd::Random(free);
    constexpr int kSolves = 200;
    fmt::print("\nThe implicit needle's step solve: SB, 0.4 mm T10 half mesh, {} elements, {} free components, h {} ms ({} solves)\n",
               needle.num_elements(), free, h, kSolves);
    fmt::print("{:>34} {:>10} {:>12} {:>12} {:>16}\n", "factorisation", "factor s", "solve ms", "nnz(L)", "max |x - x_model|/|x|");
    Eigen::VectorXd reference;
    // nnz: the factor's entries once computed (-1: not known).
    const auto measure = [&](const std::string& name, auto& solver, const auto& nnz_of) {
      const auto t0 = Clock::now();
      solver.compute(A.selfadjointView<Eigen::Lower>());
      const double factor_s = since(t0);
      Eigen::VectorXd x;
      const auto t1 = Clock::now();
      for (int k = 0; k < kSolves; ++k) x = solver.solve(rhs);
      const double solve_ms = 1e3 * since(t1) / kSolves;
      if (reference.size() == 0) reference = x;
      const double difference = (x - reference).cwiseAbs().maxCoeff() / reference.cwiseAbs().maxCoeff();
      const long nnz = nnz_of(solver);
      fmt::print("{:>34} {:>10.3f} {:>12.3f} {:>12} {:>16.2e}\n", name, factor_s, solve_ms, nnz < 0 ? std::string("-") : std::to_string(nnz), difference);
    };
    const auto unknown = [](const auto&) { return -1L; };
    const auto entries = [](const auto& f) { return static_cast<long>(f.matrixL().nestedExpression().nonZeros()); };
    {
      Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> supernodal;
      measure("CHOLMOD supernodal LLT (the model)", supernodal, unknown);
    }
    {
      Eigen::CholmodSimplicialLLT<Eigen::SparseMatrix<double>> simplicial;
      measure("CHOLMOD simplicial LLT", simplicial, unknown);
    }
    {
      Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> eigen_llt;
      measure("Eigen simplicial LLT (AMD)", eigen_llt, entries);
    }
    {
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> eigen_ldlt;
      measure("Eigen simplicial LDLT (AMD)", eigen_ldlt, entries);
    }
  }
  return 0;
}
