// The contact's parts on their own: the penalty law between one particle and a meshed rod
// (contact/needle_tissue_contact.h) against its closed form, the exchange of force between the bodies, and the
// contact surface's pull-back and triangle search (contact/contact_surface.h) under rigid motions.
#include <catch2/catch.hpp>
#include <cmath>

#include "mesher/needle_mesher.h"
#include "solver/contact/contact_surface.h"
#include "core/input_error.h"
#include "solver/contact/contact_laws.h"
#include "solver/contact/penalty_contact.h"

using namespace needle;

namespace {

constexpr double kRadius = 0.5, kLength = 4.0;  // plain rod: x in [-4, 0], axis y = z = 0

TetMesh rod_mesh() {
  NeedleMeshOptions o;
  o.order = 1;
  o.size_mm = 0.2;
  o.high_order_optimize = false;
  return mesh_needle(plain_rod_tip(2 * kRadius, kLength), false, o);
}

// One particle of spacing h (mass and volume of a cube of tissue of that size) at p moving at v.
TissueParticles one_particle(const Eigen::Vector3d& p, const Eigen::Vector3d& v, double h = 0.2, double density_g_per_mm3 = 1e-3) {
  TissueParticles t;
  t.position_mm = {p};
  t.initial_mm = t.reference_mm = {p};
  t.velocity_mm_per_ms = {v};
  t.reference_volume_mm3 = {h * h * h};
  t.mass_g = {density_g_per_mm3 * h * h * h};
  t.spacing_mm = {h};
  t.force_N = {Eigen::Vector3d::Zero()};
  t.flags = {0};
  return t;
}

struct Step {
  std::vector<Vec3d> particle_force;
  NodalForces needle_force;
  ContactReport report;
};

// One step of dt with a rigid, resting needle: the contact's begin, one evaluation at the step's end, its end.
Step contact_step(PenaltyContact& contact, const TissueParticles& particles, const Eigen::MatrixX3d& x, double dt) {
  const Eigen::MatrixX3d v = Eigen::MatrixX3d::Zero(x.rows(), 3);
  Step s;
  contact.begin_step(particles, x, v, 0.0, dt);
  contact.needle_forces(x, v, dt, s.needle_force);
  s.report = contact.report();
  contact.end_step(s.particle_force);
  return s;
}

Eigen::Vector3d total(const NodalForces& f) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& [node, force] : f) sum += force;
  return sum;
}

}  // namespace

TEST_CASE("Contact law: a particle within the skin is pushed out by k g n, k the closed form, the needle takes the opposite force",
          "[solver][contact][gmsh][slow]") {
  const TetMesh mesh = rod_mesh();
  const ContactSurface surface(mesh);
  TissueMaterial material;
  const double M = material.E_MPa * (1 - material.nu) / ((1 + material.nu) * (1 - 2 * material.nu));  // P-wave modulus
  ContactOptions options;
  options.friction = 0.0;
  const double h = 0.2;
  for (const double depth : {0.005, 0.012}) {  // outside the surface, within the 0.02 mm skin
    // Above the rod's top line (y up), halfway along, where the faceted surface meets the cylinder.
    const Eigen::Vector3d top = mesh.X.row(nearest_node(mesh, Eigen::Vector3d(-2.0, kRadius, 0.0))).transpose();
    const TissueParticles p = one_particle(top + Eigen::Vector3d(0, depth, 0), Eigen::Vector3d::Zero(), h);
    PenaltyContact contact(surface, p, material, options);
    contact.set_needle(Eigen::VectorXd::Ones(mesh.num_nodes()), std::numeric_limits<double>::infinity());  // rigid: no cap
    const Step s = contact_step(contact, p, mesh.X, 1e-4);
    const double k = options.stiffness_factor * M * h * h * h / (h * h);
    const double phi = surface.level_set().signed_distance_mm(p.position_mm[0]);
    const Eigen::Vector3d n = surface.level_set().gradient(p.position_mm[0]).normalized();
    INFO("depth " << depth << ": phi " << phi << ", n " << n.transpose() << ", force " << s.particle_force[0].transpose());
    CHECK(std::abs(phi - depth) < 0.5 * options.voxel_mm);  // the level set sees the particle where it is
    CHECK(n.y() > 0.95);                                     // pushed out of the rod's top, up
    const Eigen::Vector3d expected = k * (options.skin_mm - phi) * n;
    CHECK((s.particle_force[0] - expected).norm() < 1e-12 * expected.norm());
    CHECK(s.report.penalty_energy_mJ == Approx(0.5 * k * (options.skin_mm - phi) * (options.skin_mm - phi)).epsilon(1e-6));
    // Action and reaction: the needle's nodal forces add up to minus the particle's, to rounding.
    CHECK((total(s.needle_force) + s.particle_force[0]).norm() < 1e-12 * expected.norm());
    CHECK((s.report.force_on_needle_N + s.particle_force[0]).norm() < 1e-12 * expected.norm());
    CHECK(contact.stable_time_step_ms() == Approx(2 * std::sqrt(p.mass_g[0] / k)).epsilon(1e-12));
  }
  // Beyond the skin, nothing.
  const Eigen::Vector3d top = mesh.X.row(nearest_node(mesh, Eigen::Vector3d(-2.0, kRadius, 0.0))).transpose();
  const TissueParticles far = one_particle(top + Eigen::Vector3d(0, 0.05, 0), Eigen::Vector3d::Zero(), h);
  PenaltyContact contact(surface, far, material, options);
  contact.set_needle(Eigen::VectorXd::Ones(mesh.num_nodes()), std::numeric_limits<double>::infinity());
  const Step s = contact_step(contact, far, mesh.X, 1e-4);
  CHECK(s.particle_force[0].norm() == 0.0);
  CHECK(s.needle_force.empty());
  CHECK(s.report.particles_in_contact == 0);
}

TEST_CASE("Contact law: a particle sliding over a facet feels Coulomb friction against its sliding, capped when slow, and the damper",
          "[solver][contact][gmsh][slow]") {
  // The law of contact/needle_tissue_contact.h written out for one particle over the middle of one surface triangle,
  // in the contact's own normal n (the level set's at the particle's start), against a rigid needle at rest:
  //   g = skin - phi_start - dt n.v,  f_n = max(0, k g - c n.v),  c = zeta 2 sqrt(k m),
  //   f_t = min(mu f_n, m / (2 dt) |v_t|) against v_t = v - (n.v) n.
  const TetMesh mesh = rod_mesh();
  const ContactSurface surface(mesh);
  const TissueMaterial material;
  const double M = material.E_MPa * (1 - material.nu) / ((1 + material.nu) * (1 - 2 * material.nu));
  ContactOptions options;
  options.friction = 0.18;
  const double dt = 1e-4, h = 0.2;
  // A triangle on the rod's top, away from its ends.
  int triangle = -1;
  for (int t = 0; t < surface.num_triangles() && triangle < 0; ++t) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) c += mesh.X.row(surface.triangles()(t, k)).transpose() / 3.0;
    if (c.x() < -1.5 && c.x() > -2.5 && c.y() > 0.45) triangle = t;
  }
  REQUIRE(triangle >= 0);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) centroid += mesh.X.row(surface.triangles()(triangle, k)).transpose() / 3.0;
  const Eigen::Vector3d n = surface.level_set().gradient(centroid).normalized();
  const Eigen::Vector3d along = (Eigen::Vector3d::UnitX() - n.x() * n).normalized();  // in the tangent plane
  int cases = 0;
  for (const auto& [speed, approach_speed] : {std::pair{10.0, 0.0}, std::pair{1e-6, 0.0}, std::pair{2.0, -20.0}}) {
    const Eigen::Vector3d v = speed * along + approach_speed * n;  // mm/ms; approach_speed < 0 moves toward the needle
    const Eigen::Vector3d start = centroid + 0.01 * n;
    const TissueParticles p = one_particle(start + dt * v, v, h);
    PenaltyContact contact(surface, p, material, options);
    contact.set_needle(Eigen::VectorXd::Ones(mesh.num_nodes()), std::numeric_limits<double>::infinity());
    const Step s = contact_step(contact, p, mesh.X, dt);
    const double k = options.stiffness_factor * M * h, m = p.mass_g[0];
    const Eigen::Vector3d n_start = surface.level_set().gradient(start).normalized();
    const double g = options.skin_mm - surface.level_set().signed_distance_mm(start) - dt * n_start.dot(v);
    const double m_needle = 1.0, m_r = m * m_needle / (m + m_needle);  // every node weighs 1 g: 1 g at any surface point
    const double fn = std::max(0.0, k * g - options.damping_ratio * 2 * std::sqrt(k * m_r) * n_start.dot(v));
    const Eigen::Vector3d v_t = v - n_start.dot(v) * n_start;
    const double ft = std::min(options.friction * fn, 0.5 * m / dt * v_t.norm());
    const Eigen::Vector3d expected = fn * n_start - ft * v_t.normalized();
    INFO("speed " << speed << ", approach " << approach_speed << ": force " << s.particle_force[0].transpose() << ", expected "
                  << expected.transpose() << " (f_n " << fn << ", f_t " << ft << ")");
    REQUIRE(fn > 0);
    CHECK((s.particle_force[0] - expected).norm() < 1e-9 * expected.norm());
    // Dissipation: the damper's -f_d . v_n and the friction's f_t |v_t|, both >= 0.
    const double power = -(fn - k * g) * n_start.dot(v) + ft * v_t.norm();
    CHECK(power >= 0);
    CHECK(s.report.friction_power_mW == Approx(power).epsilon(1e-9).margin(1e-18));
    CHECK((total(s.needle_force) + s.particle_force[0]).norm() < 1e-12 * expected.norm());
    ++cases;
  }
  CHECK(cases == 3);
}

TEST_CASE("Contact surface: pull-back undoes a rigid motion of the needle, and the triangle under a point carries it by its weights",
          "[solver][contact][gmsh][slow]") {
  const TetMesh mesh = rod_mesh();
  const ContactSurface surface(mesh);
  const Eigen::MatrixX3d& X = surface.reference_positions();
  // A rigid motion: rotation about z by 3 degrees and a translation.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d d(1.5, -0.2, 0.1);
  const Eigen::MatrixX3d x = ((X * R.transpose()).rowwise() + d.transpose());
  int checked = 0;
  for (const Eigen::Vector3d& point : {Eigen::Vector3d(-1.0, 0.52, 0.0), Eigen::Vector3d(-2.5, -0.3, 0.45), Eigen::Vector3d(-3.0, 0.0, -0.51),
                                       Eigen::Vector3d(-0.5, 0.2, 0.2)}) {
    const Eigen::Vector3d current = R * point + d;
    int nearest = -1;
    double best = 1e300;
    for (int node : surface.nodes())
      if ((x.row(node).transpose() - current).norm() < best) {
        best = (x.row(node).transpose() - current).norm();
        nearest = node;
      }
    const Eigen::Vector3d back = surface.pull_back(current, nearest, x);
    INFO("point " << point.transpose() << " pulled back to " << back.transpose());
    CHECK((back - point).norm() < 1e-10);
    const double phi = surface.level_set().signed_distance_mm(point);
    const Eigen::Vector3d normal = surface.level_set().gradient(point).normalized();
    const SurfacePoint at = surface.locate(point - phi * normal);
    REQUIRE(at.triangle >= 0);
    CHECK(at.weights.sum() == Approx(1.0).epsilon(1e-12));
    CHECK(at.weights.minCoeff() >= -1e-9);
    const Eigen::Vector3i t = surface.triangles().row(at.triangle).transpose();
    const Eigen::Vector3d on_reference = at.weights[0] * X.row(t[0]).transpose() + at.weights[1] * X.row(t[1]).transpose() +
                                         at.weights[2] * X.row(t[2]).transpose();
    const Eigen::Vector3d on_current = at.weights[0] * x.row(t[0]).transpose() + at.weights[1] * x.row(t[1]).transpose() +
                                       at.weights[2] * x.row(t[2]).transpose();
    CHECK((on_current - (R * on_reference + d)).norm() < 1e-12);
    CHECK((on_reference - (point - phi * normal)).norm() < at.distance_mm + 1e-12);
    ++checked;
  }
  CHECK(checked == 4);
}

TEST_CASE("Contact laws are made by name with their traits, an unknown name lists the known ones", "[solver][contact][gmsh]") {
  // Each entry makes the law it names; the trait the coupled step and the model check read: only the kinematic law keeps
  // the needle's load constant over its step (one impulse a step), which the implicit needle needs.
  const TetMesh mesh = rod_mesh();
  const ContactSurface surface(mesh);
  const TissueParticles p = one_particle({-1.0, kRadius + 0.5, 0.0}, Eigen::Vector3d::Zero());
  for (const ContactLawEntry& entry : contact_laws()) {
    ContactOptions options;
    options.law = entry.name;
    CHECK(make_tissue_contact(surface, p, TissueMaterial{}, options)->law() == entry.name);
    CHECK(&contact_law(entry.name) == &entry);
  }
  CHECK_FALSE(contact_law("penalty").constant_over_needle_step);
  CHECK(contact_law("projection").constant_over_needle_step);
  try {
    contact_law("spring", "scene.json:3: tissue.contact.law");
    FAIL("an unknown law was found");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) == "scene.json:3: tissue.contact.law: must be penalty or projection (got 'spring')");
  }
  ContactOptions bad;
  bad.law = "spring";
  CHECK_THROWS_WITH(bad.validate(), "contact.law: must be penalty or projection (got 'spring')");
}
