#include "mesher/particle_lattice.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <vector>

#include "core/input_error.h"

namespace needle {
namespace {

// Node coordinates along one axis: equal intervals of about h on [a, b], refined on [r0, r1].
std::vector<double> axis_nodes(double a, double b, double h, std::optional<std::array<double, 2>> roi, int refinement) {
  const int n = std::max(1, static_cast<int>(std::lround((b - a) / h)));
  const double step = (b - a) / n;
  std::vector<double> nodes;
  for (int i = 0; i <= n; ++i) {
    const double x0 = a + i * step;
    nodes.push_back(i == n ? b : x0);
    if (i == n || !roi) continue;
    // An interval that only touches the region at an end is not in it (up to rounding of the nodes).
    const double tolerance = 1e-9 * step;
    if (x0 + step <= (*roi)[0] + tolerance || x0 >= (*roi)[1] - tolerance) continue;
    for (int k = 1; k < refinement; ++k) nodes.push_back(x0 + step * k / refinement);
  }
  return nodes;
}

// Half-interval sums: the length of each node's dual cell.
std::vector<double> dual_lengths(const std::vector<double>& nodes) {
  std::vector<double> length(nodes.size(), 0.0);
  for (size_t i = 0; i + 1 < nodes.size(); ++i) {
    const double half = 0.5 * (nodes[i + 1] - nodes[i]);
    length[i] += half;
    length[i + 1] += half;
  }
  return length;
}

std::vector<double> local_spacing(const std::vector<double>& nodes) {
  std::vector<double> spacing(nodes.size(), 0.0);
  for (size_t i = 0; i + 1 < nodes.size(); ++i) {
    const double d = nodes[i + 1] - nodes[i];
    spacing[i] = std::max(spacing[i], d);
    spacing[i + 1] = std::max(spacing[i + 1], d);
  }
  return spacing;
}

std::uint8_t flag_of(FaceCondition c) {
  switch (c) {
    case FaceCondition::fixed: return kParticleFixed;
    case FaceCondition::symmetry: return kParticleSymmetry;
    case FaceCondition::free: return kParticleFreeSurface;
  }
  return 0;
}

}  // namespace

FaceCondition face_condition_from_name(const std::string& name) {
  if (name == "free") return FaceCondition::free;
  if (name == "fixed") return FaceCondition::fixed;
  if (name == "symmetry") return FaceCondition::symmetry;
  throw InputError(fmt::format("unknown face condition '{}' (expected free, fixed or symmetry)", name));
}

std::string face_condition_name(FaceCondition condition) {
  switch (condition) {
    case FaceCondition::free: return "free";
    case FaceCondition::fixed: return "fixed";
    case FaceCondition::symmetry: return "symmetry";
  }
  return "?";
}

ParticleSet make_particle_lattice(const TissueBox& box, const LatticeOptions& options) {
  const double h = options.spacing_mm;
  NEEDLE_REQUIRE(std::isfinite(h) && h > 0, fmt::format("particle spacing must be a positive length in mm (got {})", h));
  for (int k = 0; k < 3; ++k) {
    NEEDLE_REQUIRE(std::isfinite(box.min_mm[k]) && std::isfinite(box.max_mm[k]) && box.max_mm[k] > box.min_mm[k],
                   fmt::format("tissue box is empty along axis {}: [{}, {}] mm", "xyz"[k], box.min_mm[k], box.max_mm[k]));
    NEEDLE_REQUIRE(h <= box.max_mm[k] - box.min_mm[k],
                   fmt::format("particle spacing {} mm is larger than the box along {} ({} mm)", h, "xyz"[k],
                               box.max_mm[k] - box.min_mm[k]));
  }
  int refinement = 1;
  if (options.region_of_interest) {
    const RegionOfInterest& r = *options.region_of_interest;
    refinement = r.refinement;
    NEEDLE_REQUIRE(refinement >= 1 && refinement <= 8, "region-of-interest refinement must be an integer in [1, 8]");
    for (int k = 0; k < 3; ++k)
      NEEDLE_REQUIRE(r.min_mm[k] < r.max_mm[k] && r.min_mm[k] < box.max_mm[k] && r.max_mm[k] > box.min_mm[k],
                     fmt::format("the region of interest does not overlap the tissue box along {}", "xyz"[k]));
  }
  double estimate = 1;
  for (int k = 0; k < 3; ++k) estimate *= (box.max_mm[k] - box.min_mm[k]) / h * refinement + 1;
  NEEDLE_REQUIRE(estimate < 5e7, fmt::format("spacing {} mm would make about {:.3g} particles (limit 5e7)", h, estimate));

  std::vector<double> nodes[3], dual[3], spacing[3];
  for (int k = 0; k < 3; ++k) {
    std::optional<std::array<double, 2>> roi;
    if (options.region_of_interest)
      roi = std::array<double, 2>{options.region_of_interest->min_mm[k], options.region_of_interest->max_mm[k]};
    nodes[k] = axis_nodes(box.min_mm[k], box.max_mm[k], h, roi, refinement);
    dual[k] = dual_lengths(nodes[k]);
    spacing[k] = local_spacing(nodes[k]);
  }
  const Eigen::Index nx = static_cast<Eigen::Index>(nodes[0].size()), ny = static_cast<Eigen::Index>(nodes[1].size()),
                     nz = static_cast<Eigen::Index>(nodes[2].size());
  ParticleSet p;
  p.nodes_per_axis = Eigen::Vector3i(static_cast<int>(nx), static_cast<int>(ny), static_cast<int>(nz));
  const Eigen::Index n = nx * ny * nz;
  p.x_mm.resize(n, 3);
  p.volume_mm3.resize(n);
  p.spacing_mm.resize(n);
  p.axis_spacing_mm.resize(n, 3);
  p.flags.resize(n);
  Eigen::Index i = 0;
  for (Eigen::Index a = 0; a < nx; ++a)
    for (Eigen::Index b = 0; b < ny; ++b)
      for (Eigen::Index c = 0; c < nz; ++c, ++i) {
        p.x_mm.row(i) << nodes[0][a], nodes[1][b], nodes[2][c];
        p.volume_mm3[i] = dual[0][a] * dual[1][b] * dual[2][c];
        p.spacing_mm[i] = std::max({spacing[0][a], spacing[1][b], spacing[2][c]});
        p.axis_spacing_mm.row(i) << spacing[0][a], spacing[1][b], spacing[2][c];
        std::uint8_t flags = 0;
        const Eigen::Index index[3] = {a, b, c}, last[3] = {nx - 1, ny - 1, nz - 1};
        for (int k = 0; k < 3; ++k) {
          if (index[k] == 0) flags |= flag_of(box.faces[2 * k]);
          if (index[k] == last[k]) flags |= flag_of(box.faces[2 * k + 1]);
        }
        p.flags[i] = flags;
      }
  return p;
}

}  // namespace needle
