#include "solver/needle/needle_stiffness.h"

#include <algorithm>
#include <fmt/format.h>
#include <set>

#include "core/input_error.h"
#include "solver/needle/needle_statics.h"

namespace needle {

Eigen::VectorXd facet_load_weights(const TetMesh& mesh, const std::vector<std::string>& tags) {
  std::set<int> wanted;
  for (const std::string& t : tags)
    if (mesh.tag_index(t) >= 0) wanted.insert(mesh.tag_index(t));
  Eigen::VectorXd w = Eigen::VectorXd::Zero(mesh.num_nodes());
  for (int f = 0; f < mesh.num_boundary_faces(); ++f) {
    if (!wanted.count(mesh.boundary_tag[f])) continue;
    const Eigen::Vector3d a = mesh.X.row(mesh.boundary_faces(f, 0)), b = mesh.X.row(mesh.boundary_faces(f, 1)),
                          c = mesh.X.row(mesh.boundary_faces(f, 2));
    const double area = 0.5 * (b - a).cross(c - a).norm();
    // Integral of the shape functions over a flat triangle: corners 1/3 (T3); corners 0 and
    // mid-edge nodes 1/3 (T6).
    if (mesh.order == 1)
      for (int k = 0; k < 3; ++k) w[mesh.boundary_faces(f, k)] += area / 3.0;
    else
      for (int k = 3; k < 6; ++k) w[mesh.boundary_faces(f, k)] += area / 3.0;
  }
  NEEDLE_REQUIRE(w.sum() > 0, fmt::format("the mesh has no faces tagged {}", fmt::join(tags, ", ")));
  return w / w.sum();
}

StiffnessResult analyse_stiffness(const FeNeedle& needle, const Eigen::Vector3d& tip_point,
                                  const std::vector<std::string>& load_tags, const std::string& clamp_tag, int modes) {
  const TetMesh& mesh = needle.mesh();
  StiffnessResult r;
  const std::vector<int> clamped = nodes_with_tag(mesh, clamp_tag);
  r.clamped_nodes = static_cast<int>(clamped.size());
  const ClampedNeedle system(needle, clamped);
  r.free_dofs = system.free_dofs();
  r.tip_node = nearest_node(mesh, tip_point);
  r.tip_node_offset_mm = (mesh.X.row(r.tip_node).transpose() - tip_point).norm();
  const Eigen::VectorXd w = facet_load_weights(mesh, load_tags);
  r.load_centroid_x_mm = w.dot(mesh.X.col(0));
  for (int axis : {1, 2}) {
    Eigen::MatrixX3d load = Eigen::MatrixX3d::Zero(mesh.num_nodes(), 3);
    load.col(axis) = w;
    const Eigen::MatrixX3d u = system.solve(load);
    (axis == 1 ? r.compliance_y_mm_per_N : r.compliance_z_mm_per_N) = u(r.tip_node, axis);
  }

  // Modes: the share of kinetic energy in each direction and the net (mass-weighted) motion say
  // which kind each one is: bending modes move the needle sideways as a whole, torsion does not.
  const std::vector<VibrationMode> computed = system.lowest_modes(std::max(modes, 2));
  const Eigen::VectorXd& m = needle.nodal_mass_g();
  const double total_mass = m.sum();
  std::vector<int> bending;
  std::vector<Eigen::Vector3d> net_motion;
  for (size_t i = 0; i < computed.size(); ++i) {
    Eigen::Vector3d share, net;
    for (int k = 0; k < 3; ++k) {
      share[k] = m.dot(computed[i].shape.col(k).cwiseAbs2());
      net[k] = m.dot(computed[i].shape.col(k));
    }
    const double modal_mass_fraction = net.squaredNorm() / (total_mass * share.sum());
    share /= share.sum();
    std::string kind = "torsion/mixed";
    if (share.x() > 0.7) kind = "axial";
    else if (share.x() < 0.2 && modal_mass_fraction > 0.01) kind = std::abs(net.y()) >= std::abs(net.z()) ? "y" : "z";
    if (kind == "y" || kind == "z") bending.push_back(static_cast<int>(i));
    net_motion.push_back(net);
    r.mode_frequencies_hz.push_back(computed[i].frequency_hz);
    r.mode_directions.push_back(kind);
  }
  // The two lowest bending modes are the first y and z bending modes (the second ones lie ~6x higher).
  // A round rod's pair is degenerate and may come out turned about the axis, so each frequency is the
  // Rayleigh quotient of the combination of the pair that moves purely in y (or z):
  // omega^2 = (a^2 omega_a^2 + b^2 omega_b^2) / (a^2 + b^2) for mass-orthonormal modes.
  NEEDLE_REQUIRE(bending.size() >= 2, "the modal analysis found fewer than two bending modes; ask for more modes");
  const int a = bending[0], b = bending[1];
  const double wa = computed[static_cast<size_t>(a)].frequency_hz, wb = computed[static_cast<size_t>(b)].frequency_hz;
  const double mass_a = m.dot(computed[static_cast<size_t>(a)].shape.rowwise().squaredNorm());
  const double mass_b = m.dot(computed[static_cast<size_t>(b)].shape.rowwise().squaredNorm());
  auto pure = [&](int other_axis) {
    // a phi_a + b phi_b with no net motion along other_axis (modes scaled to unit modal mass).
    const double ca = net_motion[static_cast<size_t>(b)][other_axis] / std::sqrt(mass_b);
    const double cb = -net_motion[static_cast<size_t>(a)][other_axis] / std::sqrt(mass_a);
    if (ca * ca + cb * cb == 0) return wa;
    return std::sqrt((ca * ca * wa * wa + cb * cb * wb * wb) / (ca * ca + cb * cb));
  };
  r.frequency_y_hz = pure(2);
  r.frequency_z_hz = pure(1);
  return r;
}

}  // namespace needle
