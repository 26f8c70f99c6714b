// RK shape functions: partition of unity and linear reproduction (values and gradients) at the
// particles and between them, on regular and jittered sets; gradients against finite differences;
// rows rebuilt without cut entries keep both properties; ellipsoidal supports on a graded lattice (the search
// against all pairs, reproduction, derivatives, and the spheres on a uniform lattice).
#include <catch2/catch.hpp>
#include <random>

#include "solver/tissue/rk_shape_functions.h"
#include "tests/solver/solver_fixtures.h"

using namespace needle;

namespace {

struct Worst {
  double unity = 0, linear = 0, gradient_unity = 0, gradient_linear = 0;
};

Worst check_rows(const RkShapeFunctions& rk, const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& centres) {
  Worst w;
  for (std::int64_t i = 0; i < rk.rows(); ++i) {
    REQUIRE(rk.valid[static_cast<size_t>(i)]);
    double sum = 0;
    Eigen::Vector3d x = Eigen::Vector3d::Zero(), g = Eigen::Vector3d::Zero();
    Eigen::Matrix3d G = Eigen::Matrix3d::Zero();
    for (std::int64_t e = rk.offset[static_cast<size_t>(i)]; e < rk.offset[static_cast<size_t>(i + 1)]; ++e) {
      const Eigen::Vector3d X = centres.row(rk.centre[static_cast<size_t>(e)]).transpose();
      const Eigen::Vector3d grad(rk.grad[static_cast<size_t>(e)][0], rk.grad[static_cast<size_t>(e)][1], rk.grad[static_cast<size_t>(e)][2]);
      sum += rk.psi[static_cast<size_t>(e)];
      x += rk.psi[static_cast<size_t>(e)] * X;
      g += grad;
      G += X * grad.transpose();
    }
    w.unity = std::max(w.unity, std::abs(sum - 1));
    w.linear = std::max(w.linear, (x - points.row(i).transpose()).norm());
    w.gradient_unity = std::max(w.gradient_unity, g.norm());
    w.gradient_linear = std::max(w.gradient_linear, (G - Eigen::Matrix3d::Identity()).norm());
  }
  return w;
}

Eigen::VectorXd radii(const ParticleSet& set, double dilation) { return dilation * set.spacing_mm; }

// The largest gap between each shape function's gradient at x and its central difference, and the largest gradient.
std::pair<double, double> gradient_against_differences(const Eigen::RowVector3d& x, const Eigen::MatrixX3d& centres, const KernelSupports& supports) {
  Eigen::MatrixX3d point(1, 3);
  point.row(0) = x;
  const RkShapeFunctions at = evaluate_rk_shape_functions(point, centres, supports);
  const double step = 1e-6;
  double worst = 0, scale = 0;
  for (int k = 0; k < 3; ++k) {
    Eigen::MatrixX3d plus = point, minus = point;
    plus(0, k) += step;
    minus(0, k) -= step;
    const RkShapeFunctions p = evaluate_rk_shape_functions(plus, centres, supports);
    const RkShapeFunctions m = evaluate_rk_shape_functions(minus, centres, supports);
    REQUIRE(p.centre == at.centre);
    REQUIRE(m.centre == at.centre);
    for (size_t e = 0; e < at.centre.size(); ++e) {
      const double fd = (p.psi[e] - m.psi[e]) / (2 * step);
      worst = std::max(worst, std::abs(fd - at.grad[e][static_cast<size_t>(k)]));
      scale = std::max(scale, std::abs(at.grad[e][static_cast<size_t>(k)]));
    }
  }
  return {worst, scale};
}

}  // namespace

TEST_CASE("RK shape functions reproduce constants and linear fields at the particles", "[solver][rk]") {
  for (double jitter : {0.0, 0.3}) {
    const ParticleSet set = needle_test::jittered(needle_test::free_box({0, 0, 0}, {4, 3, 2}, 0.5), jitter);
    const RkShapeFunctions rk = build_rk_shape_functions(set.x_mm, radii(set, 1.8));
    const Worst w = check_rows(rk, set.x_mm, set.x_mm);
    INFO("jitter " << jitter);
    CHECK(w.unity < 1e-12);
    CHECK(w.linear < 1e-12);
    CHECK(w.gradient_unity < 1e-11);   // 1/mm, h = 0.5 mm
    CHECK(w.gradient_linear < 1e-12);
    // The transpose lists every entry exactly once.
    CHECK(rk.column_entry.size() == rk.centre.size());
  }
}

TEST_CASE("RK shape functions reproduce linear fields between particles", "[solver][rk]") {
  const ParticleSet set = needle_test::jittered(needle_test::free_box({0, 0, 0}, {4, 3, 2}, 0.5), 0.3);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::MatrixX3d points(300, 3);
  for (int i = 0; i < 300; ++i) points.row(i) << 4 * u(rng), 3 * u(rng), 2 * u(rng);
  const RkShapeFunctions rk = evaluate_rk_shape_functions(points, set.x_mm, radii(set, 1.8));
  const Worst w = check_rows(rk, points, set.x_mm);
  CHECK(w.unity < 1e-12);
  CHECK(w.linear < 1e-12);
  CHECK(w.gradient_unity < 1e-11);
  CHECK(w.gradient_linear < 1e-12);
}

TEST_CASE("RK gradients are the derivatives of the shape functions", "[solver][rk]") {
  const ParticleSet set = needle_test::jittered(needle_test::free_box({0, 0, 0}, {3, 3, 3}, 0.5), 0.25);
  const std::pair<double, double> gap = gradient_against_differences(Eigen::RowVector3d(1.37, 1.61, 1.23), set.x_mm, radii(set, 1.8));
  CHECK(gap.second > 0.1);
  CHECK(gap.first < 1e-6 * gap.second);
}

TEST_CASE("Rows rebuilt without cut entries keep reproduction, too few entries invalidate a row", "[solver][rk]") {
  const ParticleSet set = needle_test::free_box({0, 0, 0}, {3, 3, 3}, 0.5);
  const Eigen::VectorXd r = radii(set, 1.8);
  RkShapeFunctions rk = build_rk_shape_functions(set.x_mm, r);
  const std::int64_t row = 100;
  const std::int64_t begin = rk.offset[row], end = rk.offset[row + 1];
  for (std::int64_t e = begin; e < end; e += 3)
    if (rk.centre[static_cast<size_t>(e)] != row) rk.cut[static_cast<size_t>(e)] = 1;
  rebuild_rk_rows(rk, {row}, set.x_mm, set.x_mm, r);
  REQUIRE(rk.valid[row]);
  double sum = 0;
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (std::int64_t e = begin; e < end; ++e) {
    if (rk.cut[static_cast<size_t>(e)]) CHECK(rk.psi[static_cast<size_t>(e)] == 0.0);
    sum += rk.psi[static_cast<size_t>(e)];
    x += rk.psi[static_cast<size_t>(e)] * set.x_mm.row(rk.centre[static_cast<size_t>(e)]).transpose();
  }
  CHECK(std::abs(sum - 1) < 1e-12);
  CHECK((x - set.x_mm.row(row).transpose()).norm() < 1e-12);
  // Cut all but self and two neighbours: 3 centres cannot carry a linear basis.
  int kept = 0;
  for (std::int64_t e = begin; e < end; ++e)
    if (rk.centre[static_cast<size_t>(e)] != row && kept++ >= 2) rk.cut[static_cast<size_t>(e)] = 1;
  rebuild_rk_rows(rk, {row}, set.x_mm, set.x_mm, r);
  CHECK_FALSE(rk.valid[row]);
}

TEST_CASE("The transpose's copy of the values follows every rebuilt and cleared row", "[solver][rk]") {
  const ParticleSet set = needle_test::jittered(needle_test::free_box({0, 0, 0}, {3, 3, 3}, 0.5), 0.2);
  const Eigen::VectorXd r = radii(set, 1.8);
  RkShapeFunctions rk = build_rk_shape_functions(set.x_mm, r);
  const auto mismatches = [&rk] {
    int count = 0;
    for (std::int64_t c = 0; c < rk.entries(); ++c) {
      const std::int64_t e = rk.column_entry[static_cast<size_t>(c)];
      const std::array<double, 4>& v = rk.column_value[static_cast<size_t>(c)];
      const Vec3& g = rk.grad[static_cast<size_t>(e)];
      if (rk.entry_slot[static_cast<size_t>(e)] != c || v[0] != rk.psi[static_cast<size_t>(e)] || v[1] != g[0] || v[2] != g[1] || v[3] != g[2]) ++count;
    }
    return count;
  };
  REQUIRE(rk.column_value.size() == rk.centre.size());
  CHECK(mismatches() == 0);
  // Cut every other entry of a few rows and rebuild them: their values change, and so must the copies.
  std::vector<std::int64_t> rows = {3, 40, 77};
  const std::vector<double> psi_before = rk.psi;
  for (std::int64_t row : rows)
    for (std::int64_t e = rk.offset[static_cast<size_t>(row)]; e < rk.offset[static_cast<size_t>(row + 1)]; e += 2)
      if (rk.centre[static_cast<size_t>(e)] != row) rk.cut[static_cast<size_t>(e)] = 1;
  rebuild_rk_rows(rk, rows, set.x_mm, set.x_mm, r);
  CHECK(rk.psi != psi_before);
  CHECK(mismatches() == 0);
  // A row cleared entry by entry (a particle that stops integrating) clears its copies.
  for (std::int64_t e = rk.offset[5]; e < rk.offset[6]; ++e) set_rk_entry(rk, e, 0, {0, 0, 0});
  CHECK(mismatches() == 0);
  // Columns gather the same sums as rows do: sum over all entries of psi, by rows and by columns.
  double by_rows = 0, by_columns = 0;
  for (double p : rk.psi) by_rows += std::abs(p);
  for (const std::array<double, 4>& v : rk.column_value) by_columns += std::abs(v[0]);
  CHECK(by_columns == Approx(by_rows).epsilon(1e-12));
}

namespace {

// A lattice graded as the run's is: 0.2 mm intervals along x everywhere and in a band around the path,
// 0.4 mm across y and z outside it (tensor), or 0.4 mm along every axis outside the band (nested).
ParticleSet graded_lattice(LatticeGrading grading = LatticeGrading::tensor) {
  TissueBox box;
  box.min_mm = {0, -1.6, 0};
  box.max_mm = {2.4, 1.6, 1.6};
  box.faces.fill(FaceCondition::free);
  LatticeOptions o;
  o.spacing_mm = 0.4;
  o.region_of_interest = RegionOfInterest{{0, -0.4, 0}, {2.4, 0.4, 0.4}, 2, grading};
  return make_particle_lattice(box, o);
}

KernelSupports ellipsoids(const ParticleSet& set, double dilation) { return KernelSupports::ellipsoids(dilation * set.axis_spacing_mm); }

}  // namespace

TEST_CASE("Ellipsoidal supports: the covering centres are those inside each ellipsoid, found by a search over all pairs", "[solver][rk]") {
  const ParticleSet set = graded_lattice();
  const KernelSupports s = ellipsoids(set, 1.8);
  const NeighbourLists lists = find_covering_centres(set.x_mm, set.x_mm, s);
  std::int64_t mismatched = 0, total = 0, sphere_total = 0;
  for (std::int64_t i = 0; i < set.num_particles(); ++i) {
    std::vector<std::int32_t> expected;
    for (std::int32_t j = 0; j < set.num_particles(); ++j) {
      const Eigen::Vector3d d = set.x_mm.row(i) - set.x_mm.row(j);
      double q = 0;
      for (int k = 0; k < 3; ++k) q += (d[k] / s.radius_mm(j, k)) * (d[k] / s.radius_mm(j, k));
      if (q < 1) expected.push_back(j);
      if (d.norm() < 1.8 * set.spacing_mm[j]) ++sphere_total;
    }
    const std::vector<std::int32_t> found(lists.index.begin() + lists.offset[static_cast<size_t>(i)],
                                          lists.index.begin() + lists.offset[static_cast<size_t>(i + 1)]);
    if (found != expected) ++mismatched;
    total += static_cast<std::int64_t>(expected.size());
  }
  CHECK(mismatched == 0);
  // The point of the ellipsoids: on this lattice a sphere of 1.8 x the largest interval holds far more centres.
  INFO("entries: ellipsoids " << total << ", spheres " << sphere_total);
  CHECK(sphere_total > 3 * total / 2);
}

TEST_CASE("Ellipsoidal supports reproduce linear fields at the particles and between them, with exact derivatives", "[solver][rk]") {
  const ParticleSet set = graded_lattice();
  const KernelSupports s = ellipsoids(set, 1.8);
  const RkShapeFunctions rk = build_rk_shape_functions(set.x_mm, s);
  const Worst at = check_rows(rk, set.x_mm, set.x_mm);
  CHECK(at.unity < 1e-12);
  CHECK(at.linear < 1e-12);
  CHECK(at.gradient_unity < 1e-10);
  CHECK(at.gradient_linear < 1e-12);

  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::MatrixX3d points(200, 3);
  for (int i = 0; i < 200; ++i) points.row(i) << 2.4 * u(rng), -1.6 + 3.2 * u(rng), 1.6 * u(rng);
  const Worst between = check_rows(evaluate_rk_shape_functions(points, set.x_mm, s), points, set.x_mm);
  CHECK(between.unity < 1e-12);
  CHECK(between.linear < 1e-12);
  CHECK(between.gradient_linear < 1e-11);

  // Derivatives by central differences at a point where fine and coarse supports overlap.
  const std::pair<double, double> gap = gradient_against_differences(Eigen::RowVector3d(1.13, 0.47, 0.39), set.x_mm, s);
  CHECK(gap.second > 0.1);
  CHECK(gap.first < 1e-6 * gap.second);
}

TEST_CASE("On a uniform lattice ellipsoidal supports are the spheres", "[solver][rk]") {
  const ParticleSet set = needle_test::free_box({0, 0, 0}, {2, 2, 2}, 0.5);
  Eigen::MatrixX3d axes(set.num_particles(), 3);
  axes.col(0) = axes.col(1) = axes.col(2) = 1.8 * set.spacing_mm;
  const RkShapeFunctions sphere = build_rk_shape_functions(set.x_mm, radii(set, 1.8));
  const RkShapeFunctions ellipsoid = build_rk_shape_functions(set.x_mm, KernelSupports::ellipsoids(axes));
  REQUIRE(ellipsoid.centre == sphere.centre);
  double worst = 0;
  for (size_t e = 0; e < sphere.psi.size(); ++e) {
    worst = std::max(worst, std::abs(ellipsoid.psi[e] - sphere.psi[e]));
    for (size_t k = 0; k < 3; ++k) worst = std::max(worst, std::abs(ellipsoid.grad[e][k] - sphere.grad[e][k]));
  }
  CHECK(worst < 1e-12);
}

TEST_CASE("On a nested lattice every row is valid and reproduces linear fields, with either support", "[solver][rk]") {
  const ParticleSet set = graded_lattice(LatticeGrading::nested);
  for (const KernelSupports& supports : {KernelSupports(Eigen::VectorXd(1.8 * set.spacing_mm)), KernelSupports::ellipsoids(1.8 * set.axis_spacing_mm)}) {
    const RkShapeFunctions rk = build_rk_shape_functions(set.x_mm, supports);
    const Worst w = check_rows(rk, set.x_mm, set.x_mm);  // requires every row valid
    INFO("spherical " << supports.spherical);
    CHECK(w.unity < 1e-12);
    CHECK(w.linear < 1e-12);
    CHECK(w.gradient_unity < 1e-10);
    CHECK(w.gradient_linear < 1e-12);
  }
}
