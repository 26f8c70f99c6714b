// The needle's FE model against beam theory: tip compliance of a plain rod and of the grooved paper
// presets, and the rod's first bending frequency. References are computed here, from closed forms and
// from the ideal solid's exact sections (geometry/exact_measures.h), never from the FE code.
#include <catch2/catch.hpp>
#include <cmath>

#include "geometry/exact_measures.h"
#include "geometry/grinding_recipe.h"
#include "mesher/needle_mesher.h"
#include "mesher/tet_element.h"
#include "solver/needle/fe_needle.h"
#include "solver/needle/needle_stiffness.h"

using namespace needle;

namespace {

FeNeedle fe_model(const TipGeometry& tip, int order, double size_mm) {
  NeedleMeshOptions o;
  o.order = order;
  o.size_mm = size_mm;
  o.high_order_optimize = false;
  return FeNeedle(mesh_needle(tip, false, o), NeedleMaterial{});
}

std::vector<std::string> facet_names(const TipGeometry& tip) {
  std::vector<std::string> names;
  for (const auto& f : tip.facets) names.push_back(f.name);
  return names;
}

// Unit-load method with the exact sections, trapezoid rule on a fine grid (independent of
// solver/beam_reference): delta = int (x_load - x)(0 - x) / (E I(x)) dx from the clamp to the load.
double beam_compliance(const TipGeometry& tip, double load_x, bool y_direction) {
  ExactOptions exact;
  exact.circle_vertices = 2048;
  const double E = NeedleMaterial{}.youngs_modulus_MPa, a = tip.base_x_mm;
  const int n = 4000;
  const double h = (load_x - a) / n;
  double sum = 0;
  for (int i = 0; i <= n; ++i) {
    const double x = std::min(a + i * h, load_x - 1e-9);
    const SectionProperties s = exact_section(tip, x, exact);
    const double f = (load_x - x) * (-x) / (E * (y_direction ? s.I_z_mm4 : s.I_y_mm4));
    sum += (i == 0 || i == n ? 0.5 : 1.0) * f;
  }
  return sum * h;
}

}  // namespace

TEST_CASE("T10 shape functions: partition of unity, and the lumped mass is the consistent diagonal scaled", "[solver][needle]") {
  for (int order : {1, 2}) {
    const Eigen::Vector3d xi(0.2, 0.3, 0.1);
    CHECK(std::abs(tet_shape_values(order, xi).sum() - 1.0) < 1e-14);
    CHECK(tet_shape_gradients(order, xi).colwise().sum().norm() < 1e-14);
    // Gradients against central differences.
    const Eigen::MatrixXd G = tet_shape_gradients(order, xi);
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d[k] = 1e-6;
      const Eigen::VectorXd fd = (tet_shape_values(order, xi + d) - tet_shape_values(order, xi - d)) / 2e-6;
      CHECK((fd - G.col(k)).norm() < 1e-8);
    }
  }
  // Consistent-mass diagonal of a T10 by the barycentric monomial formula
  // int L0^a L1^b L2^c L3^d dV = a! b! c! d! 3! V / (a + b + c + d + 3)!:
  // corner int (2L^2 - L)^2 = V/70, edge int 16 L_i^2 L_j^2 = 8V/105.
  const double corner = 4 * 24.0 * 6 / 5040 - 4 * 6.0 * 6 / 720 + 2.0 * 6 / 120;
  const double edge = 16 * 4.0 * 6 / 5040;
  const auto& f = tet_lumped_mass_fractions(2);
  const double diagonal_sum = 4 * corner + 6 * edge;
  CHECK(f[0] == Approx(corner / diagonal_sum).epsilon(1e-12));
  CHECK(f[9] == Approx(edge / diagonal_sum).epsilon(1e-12));
  // Quadrature rules integrate what they claim: the 4-point rule is exact for quadratics.
  double integral = 0;
  for (const auto& p : tet_quadrature(2)) integral += p.weight * p.xi.x() * p.xi.y();
  CHECK(integral == Approx(1.0 / 120).epsilon(1e-12));  // int L1 L2 over the reference tet = 1! 1! 3! (1/6) / 5!
}

TEST_CASE("FE forces vanish under rigid motion of any size and conserve momentum", "[solver][needle]") {
  const FeNeedle needle = fe_model(plain_rod_tip(1.0, 5.0), 2, 0.4);
  const Eigen::MatrixX3d& X = needle.mesh().X;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1.3, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  Eigen::MatrixX3d x = (X * R.transpose()).rowwise() + Eigen::RowVector3d(3.0, -2.0, 1.0);
  Eigen::MatrixX3d f;
  const double energy = needle.internal_forces(x, f);
  CHECK(energy < 1e-18);
  CHECK(f.cwiseAbs().maxCoeff() < 1e-6);  // N; a 1e-3 strain would give ~10 N
  // Any deformation: the forces sum to zero (linear momentum) and their moment too (angular momentum).
  x = X + 1e-3 * Eigen::MatrixX3d::Random(X.rows(), 3);
  needle.internal_forces(x, f);
  CHECK(f.colwise().sum().norm() < 1e-9 * f.cwiseAbs().maxCoeff() * X.rows());
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (int i = 0; i < X.rows(); ++i) moment += Eigen::Vector3d(x.row(i)).cross(Eigen::Vector3d(f.row(i)));
  CHECK(moment.norm() < 1e-9 * f.cwiseAbs().maxCoeff() * X.rows());
  // The energy's derivative is minus the force (finite differences on one node).
  const int node = static_cast<int>(X.rows() / 2);
  for (int k = 0; k < 3; ++k) {
    Eigen::MatrixX3d xp = x, xm = x;
    xp(node, k) += 1e-7;
    xm(node, k) -= 1e-7;
    Eigen::MatrixX3d scratch;
    const double dW = (needle.internal_forces(xp, scratch) - needle.internal_forces(xm, scratch)) / 2e-7;
    CHECK(-dW == Approx(f(node, k)).epsilon(1e-4).margin(1e-6));
  }
}

TEST_CASE("Plain rod: tip compliance and first bending frequency within 2 % of Euler-Bernoulli", "[solver][needle][gmsh][slow]") {
  const NeedleMaterial steel;
  for (double length : {30.0, 40.0}) {
    const TipGeometry tip = plain_rod_tip(1.0, length);
    const FeNeedle needle = fe_model(tip, 2, 0.25);
    const StiffnessResult r = analyse_stiffness(needle, tip.tip_point, {"end"});
    const double I = M_PI * std::pow(0.5, 4) / 4, area = M_PI * 0.25;
    const double compliance = std::pow(length, 3) / (3 * steel.youngs_modulus_MPa * I);
    const double beta = 1.8751040687119611;
    const double frequency = beta * beta / (2 * M_PI * length * length) *
                             std::sqrt(steel.youngs_modulus_MPa * I / (steel.density_g_per_mm3 * area)) * 1000.0;
    INFO("L " << length << " compliance " << r.compliance_y_mm_per_N << " / " << r.compliance_z_mm_per_N << " vs " << compliance
              << ", frequency " << r.frequency_y_hz << " / " << r.frequency_z_hz << " vs " << frequency);
    CHECK(std::abs(r.compliance_y_mm_per_N / compliance - 1) < 0.02);
    CHECK(std::abs(r.compliance_z_mm_per_N / compliance - 1) < 0.02);
    CHECK(std::abs(r.frequency_y_hz / frequency - 1) < 0.02);
    CHECK(std::abs(r.frequency_z_hz / frequency - 1) < 0.02);
    CHECK(r.tip_node_offset_mm < 0.1);  // the end face's centre need not be a node
  }
}

TEST_CASE("Grooved presets: tip compliance within 2 % of Euler-Bernoulli with the real sections", "[solver][needle][gmsh][slow]") {
  // Free lengths 40 and 50 mm. The FE model is ~0.13 mm/N (y) more compliant than beam theory,
  // independent of length: the sudden section change at the groove's back end, where the neutral
  // axis jumps, is a 3D effect beam theory does not have (docs/solver.md). At 30 mm that is 2.0-2.1 %.
  for (const std::string preset : {"SB", "HMB"}) {
    for (double length : {40.0, 50.0}) {
      GrindingRecipe recipe = preset_recipe(preset);
      recipe.rod.length_mm = length;
      const TipGeometry tip = resolve_tip(recipe);
      const FeNeedle needle = fe_model(tip, 2, 0.25);
      const StiffnessResult r = analyse_stiffness(needle, tip.tip_point, facet_names(tip));
      const double beam_y = beam_compliance(tip, r.load_centroid_x_mm, true);
      const double beam_z = beam_compliance(tip, r.load_centroid_x_mm, false);
      INFO(preset << " L " << length << " y " << r.compliance_y_mm_per_N << " vs " << beam_y << ", z "
                  << r.compliance_z_mm_per_N << " vs " << beam_z);
      CHECK(std::abs(r.compliance_y_mm_per_N / beam_y - 1) < 0.02);
      CHECK(std::abs(r.compliance_z_mm_per_N / beam_z - 1) < 0.02);
      CHECK(r.tip_node_offset_mm < 1e-9);  // A is a vertex of the solid, so a node
      // The groove makes the needle much softer in y than in z (it thins the section in y).
      CHECK(r.compliance_y_mm_per_N > 1.5 * r.compliance_z_mm_per_N);
      CHECK(r.frequency_y_hz < r.frequency_z_hz);
    }
  }
}
