#include "solver/contact/needle_tissue_contact.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <tuple>

#include "core/input_error.h"
#include "solver/contact/contact_laws.h"
#include "core/parallel.h"

namespace needle {

std::string ContactOptions::describe() const {
  const ContactOptions defaults;
  if (skin_mm == defaults.skin_mm && stiffness_factor == defaults.stiffness_factor) return "";
  return fmt::format("the contact's skin is {:g} mm and its stiffness factor {:g} (the defaults: {:g} and {:g})", skin_mm, stiffness_factor,
                     defaults.skin_mm, defaults.stiffness_factor);
}

void ContactOptions::validate(const std::string& where) const {
  contact_law(law, where + ".law");  // InputError for an unknown law
  NEEDLE_REQUIRE(std::isfinite(friction) && friction >= 0, fmt::format("{}: friction must be zero or positive (got {})", where, friction));
  NEEDLE_REQUIRE(std::isfinite(stiffness_factor) && stiffness_factor > 0 && stiffness_factor <= 1e4,
                 fmt::format("{}: stiffness_factor must be in (0, 1e4] (got {})", where, stiffness_factor));
  NEEDLE_REQUIRE(std::isfinite(skin_mm) && skin_mm >= 0, fmt::format("{}: skin_mm must be zero or positive (got {})", where, skin_mm));
  NEEDLE_REQUIRE(std::isfinite(damping_ratio) && damping_ratio >= 0 && damping_ratio <= 1,
                 fmt::format("{}: damping_ratio must be in [0, 1] (got {})", where, damping_ratio));
  NEEDLE_REQUIRE(std::isfinite(needle_stiffness_scale) && needle_stiffness_scale > 0 && needle_stiffness_scale <= 0.5,
                 fmt::format("{}: needle_stiffness_scale must be in (0, 0.5] (got {})", where, needle_stiffness_scale));
  NEEDLE_REQUIRE(std::isfinite(voxel_mm) && voxel_mm >= 1e-3 && voxel_mm <= 0.2,
                 fmt::format("{}: voxel_mm must be in [0.001, 0.2] (got {})", where, voxel_mm));
}

NeedleTissueContact::NeedleTissueContact(const ContactSurface& surface, const TissueParticles& particles, const ContactOptions& options)
    : surface_(surface), options_(options) {
  options_.validate();
  mass_ = particles.mass_g;
  node_cell_mm_ = surface_.node_search_radius_mm();
  report_.facets.assign(surface_.tag_names().size(), FacetContact{});
}

void NeedleTissueContact::set_needle(const Eigen::VectorXd& nodal_mass_g, double time_step_ms) {
  NEEDLE_REQUIRE(nodal_mass_g.size() == surface_.reference_positions().rows(), "contact: one needle mass per node");
  NEEDLE_REQUIRE(time_step_ms > 0, "contact: the needle's step must be positive");
  needle_mass_ = nodal_mass_g;
  needle_dt_ms_ = time_step_ms;
}

void NeedleTissueContact::build_node_grid(const Eigen::MatrixX3d& x) {
  const std::vector<int>& nodes = surface_.nodes();
  box_lo_ = box_hi_ = x.row(nodes.front()).transpose();
  for (int n : nodes) {
    box_lo_ = box_lo_.cwiseMin(x.row(n).transpose());
    box_hi_ = box_hi_.cwiseMax(x.row(n).transpose());
  }
  node_origin_ = box_lo_.array() - 2 * node_cell_mm_;
  // A dense grid (the needle's box and two cells around it), each cell's nodes in increasing order with their
  // positions beside them: a counting sort over the nodes, which the search then reads cell by cell.
  std::vector<int> order(nodes.begin(), nodes.end());
  std::sort(order.begin(), order.end());
  std::vector<Eigen::Vector3i> cells(order.size());
  node_grid_dims_ = Eigen::Vector3i::Zero();
  for (size_t k = 0; k < order.size(); ++k) {
    cells[k] = ((x.row(order[k]).transpose() - node_origin_) / node_cell_mm_).array().floor().cast<int>();
    node_grid_dims_ = node_grid_dims_.cwiseMax(cells[k] + Eigen::Vector3i::Constant(3));
  }
  node_cell_start_.assign(static_cast<size_t>(node_grid_dims_.prod()) + 1, 0);
  std::vector<int> cell(order.size());
  for (size_t k = 0; k < order.size(); ++k) {
    cell[k] = (cells[k].z() * node_grid_dims_.y() + cells[k].y()) * node_grid_dims_.x() + cells[k].x();
    ++node_cell_start_[static_cast<size_t>(cell[k]) + 1];
  }
  for (size_t c = 1; c < node_cell_start_.size(); ++c) node_cell_start_[c] += node_cell_start_[c - 1];
  node_cell_nodes_.resize(order.size());
  node_cell_points_.resize(order.size());
  std::vector<int> fill(node_cell_start_.begin(), node_cell_start_.end() - 1);
  for (size_t k = 0; k < order.size(); ++k) {
    const size_t e = static_cast<size_t>(fill[static_cast<size_t>(cell[k])]++);
    node_cell_nodes_[e] = order[k];
    node_cell_points_[e] = x.row(order[k]).transpose();
  }
}

int NeedleTissueContact::nearest_surface_node(const Eigen::Vector3d& p) const {
  // The nearest surface node closer than the cell size r (so in the 27 cells around p's). Of equally near nodes
  // the first in x-major cell order (x, then y, then z) and then in node number wins, as a scan of the 27 cells in
  // that order finds it. p's own cell is read first and a cell farther from p than the best so far is skipped
  // (it holds no node as near: the slack is far above the rounding of the cell's bounds).
  if (!p.allFinite()) return -1;
  const double r = node_cell_mm_, slack = 1e-9 * r;
  const Eigen::Vector3i c = ((p - node_origin_) / r).array().floor().cast<int>();
  int best = -1;
  Eigen::Vector3i best_cell = Eigen::Vector3i::Zero();
  double best_d2 = r * r, reach = r + slack;
  const auto visit = [&](const Eigen::Vector3i& cell) {
    if ((cell.array() < 0).any() || (cell.array() >= node_grid_dims_.array()).any()) return;
    const Eigen::Vector3d lo = node_origin_ + r * cell.cast<double>();
    const Eigen::Vector3d gap = (lo - p).cwiseMax(p - lo - Eigen::Vector3d::Constant(r)).cwiseMax(0.0);
    if (gap.squaredNorm() > reach * reach) return;
    const size_t id = static_cast<size_t>((cell.z() * node_grid_dims_.y() + cell.y()) * node_grid_dims_.x() + cell.x());
    for (int e = node_cell_start_[id]; e < node_cell_start_[id + 1]; ++e) {
      const double d2 = (node_cell_points_[static_cast<size_t>(e)] - p).squaredNorm();
      if (d2 > best_d2) continue;
      const int node = node_cell_nodes_[static_cast<size_t>(e)];
      const bool earlier = best >= 0 && std::make_tuple(cell.x(), cell.y(), cell.z(), node) <
                                            std::make_tuple(best_cell.x(), best_cell.y(), best_cell.z(), best);
      if (d2 < best_d2 || earlier) {
        best_d2 = d2;
        best = node;
        best_cell = cell;
        reach = std::sqrt(best_d2) + slack;
      }
    }
  };
  visit(c);
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int k = -1; k <= 1; ++k)
        if (i || j || k) visit(c + Eigen::Vector3i(i, j, k));
  return best;
}

void NeedleTissueContact::probe(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x, const std::vector<double>& reach,
                                bool same_needle, std::vector<Probe>* out) {
  std::vector<Probe>& probes = out ? *out : probes_;
  if (!same_needle) build_node_grid(needle_x);
  double max_reach = 0;
  for (double r : reach) max_reach = std::max(max_reach, r);
  const double margin = node_cell_mm_ + options_.skin_mm + max_reach;
  const Eigen::Vector3d lo = box_lo_.array() - margin, hi = box_hi_.array() + margin;
  const NeedleLevelSet& level_set = surface_.level_set();
  const Eigen::MatrixX3i& tri = surface_.triangles();
  const Eigen::MatrixX3d& X0 = surface_.reference_positions();
  const double skin = options_.skin_mm;
  // The needle's own box (with a half model's mirror image, which the level set closes the surface with). A
  // particle farther outside it than the skin, its reach and a slack is outside the needle and beyond contact:
  // the search below would find it so, as the slack (5 voxels and 0.1 mm) is far above the errors of the
  // pull-back and of the level set's interpolation. Most of the particles around the needle are that far.
  Eigen::Vector3d needle_lo, needle_hi;
  surface_.closed_bounds(needle_x, needle_lo, needle_hi);
  const double slack = 0.1 + 5 * options_.voxel_mm;
  probes = parallel_collect<Probe>(static_cast<std::int64_t>(x.size()), [&](std::int64_t i, std::vector<Probe>& found) {
    const size_t s = static_cast<size_t>(i);
    const Eigen::Vector3d p = x[s];
    if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) return;
    const double beyond = skin + reach[s] + slack;
    if ((needle_lo - p).cwiseMax(p - needle_hi).cwiseMax(0.0).squaredNorm() > beyond * beyond) return;
    const int node = nearest_surface_node(p);
    if (node < 0) return;
    const Eigen::Vector3d X = surface_.pull_back(p, node, needle_x);
    Probe& probe = found.emplace_back();
    probe.index = static_cast<int>(i);
    const double phi = level_set.signed_distance_mm(X);
    probe.phi = phi;
    probe.inside = phi < 0;
    if (phi >= skin + reach[s]) return;
    Eigen::Vector3d normal = level_set.gradient(X);
    if (!(normal.norm() > 1e-6)) return;  // outside the band: farther than any reach
    normal.normalize();
    Pair& pair = probe.pair;
    pair.particle = static_cast<int>(i);
    const SurfacePoint at = surface_.locate(X - phi * normal);
    if (at.triangle >= 0) {
      pair.triangle = at.triangle;
      pair.weights = at.weights;
      // Turn the reference normal with the triangle under the point.
      const auto corner = [&](const Eigen::MatrixX3d& m, int k) { return m.row(tri(at.triangle, k)).transpose().eval(); };
      const Eigen::Vector3d n_ref = (corner(X0, 1) - corner(X0, 0)).cross(corner(X0, 2) - corner(X0, 0)).normalized();
      const Eigen::Vector3d n_cur =
          (corner(needle_x, 1) - corner(needle_x, 0)).cross(corner(needle_x, 2) - corner(needle_x, 0)).normalized();
      if (n_ref.allFinite() && n_cur.allFinite()) normal = (normal + n_cur - n_ref).normalized();
    } else {
      pair.node = node;
    }
    pair.normal = normal;
    pair.particle_start = p;
    pair.surface_start = surface_point(pair, needle_x);
    pair.gap_start = skin - phi;
    probe.near = true;
  });
}

Eigen::Vector3d NeedleTissueContact::surface_point(const Pair& pair, const Eigen::MatrixX3d& needle) const {
  if (pair.triangle < 0) return needle.row(pair.node).transpose();
  const Eigen::MatrixX3i& tri = surface_.triangles();
  return pair.weights[0] * needle.row(tri(pair.triangle, 0)).transpose() + pair.weights[1] * needle.row(tri(pair.triangle, 1)).transpose() +
         pair.weights[2] * needle.row(tri(pair.triangle, 2)).transpose();
}

InsideReport NeedleTissueContact::classify(const TissueParticles& particles, const Eigen::MatrixX3d& needle_x) {
  probe(particles.position_mm, needle_x, std::vector<double>(static_cast<size_t>(particles.size()), 0.0));
  InsideReport r;
  for (size_t i = 0; i < probes_.size(); ++i) {
    const Probe& p = probes_[i];
    if (p.inside) {
      ++r.particles_inside;
      r.max_depth_mm = std::max(r.max_depth_mm, -p.phi);
    }
  }
  return r;
}

double NeedleTissueContact::needle_mass_at(const Pair& pair) const {
  if (needle_mass_.size() == 0) return std::numeric_limits<double>::infinity();
  const Eigen::MatrixX3i& tri = surface_.triangles();
  return pair.triangle >= 0 ? pair.weights[0] * needle_mass_[tri(pair.triangle, 0)] + pair.weights[1] * needle_mass_[tri(pair.triangle, 1)] +
                                  pair.weights[2] * needle_mass_[tri(pair.triangle, 2)]
                            : needle_mass_[pair.node];
}

void NeedleTissueContact::clear_report_forces() {
  report_.particles_in_contact = 0;
  report_.penalty_energy_mJ = 0;
  report_.force_on_needle_N.setZero();
  report_.facets.assign(surface_.tag_names().size(), FacetContact{});
}

void NeedleTissueContact::book_needle_force(const Pair& pair, const Eigen::Vector3d& f, double normal_N, double friction_N, NodalForces& out) {
  if (pair.triangle >= 0) {
    const Eigen::MatrixX3i& tri = surface_.triangles();
    for (int c = 0; c < 3; ++c) out.emplace_back(tri(pair.triangle, c), pair.weights[c] * f);
    FacetContact& facet = report_.facets[static_cast<size_t>(surface_.triangle_tag(pair.triangle))];
    ++facet.particles;
    facet.normal_N += normal_N;
    facet.friction_N += friction_N;
    facet.force_N += f;
  } else {
    out.emplace_back(pair.node, f);
  }
  ++report_.particles_in_contact;
  report_.force_on_needle_N += f;
}

std::vector<std::uint8_t> NeedleTissueContact::in_contact() const {
  std::vector<std::uint8_t> flags(mass_.size(), 0);
  for (const auto& [p, triangle] : contacts_) flags[static_cast<size_t>(p)] = 1;
  return flags;
}

std::vector<Eigen::Vector3d> NeedleTissueContact::pull_back(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x) {
  build_node_grid(needle_x);
  std::vector<Eigen::Vector3d> out(x.size(), Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  parallel_for(static_cast<std::int64_t>(x.size()), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const size_t s = static_cast<size_t>(i);
      const Eigen::Vector3d p = x[s];
      if ((p.array() < box_lo_.array() - node_cell_mm_).any() || (p.array() > box_hi_.array() + node_cell_mm_).any()) continue;
      const int node = nearest_surface_node(p);
      if (node >= 0) out[s] = surface_.pull_back(p, node, needle_x);
    }
  });
  return out;
}


}  // namespace needle
