#include "mesher/particle_lattice.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <optional>
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

// The flags of a particle at x from the box faces it lies on (within tolerance).
std::uint8_t face_flags(const TissueBox& box, const Eigen::Vector3d& x, double tolerance) {
  std::uint8_t flags = 0;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(x[k] - box.min_mm[k]) <= tolerance) flags |= flag_of(box.faces[static_cast<size_t>(2 * k)]);
    if (std::abs(x[k] - box.max_mm[k]) <= tolerance) flags |= flag_of(box.faces[static_cast<size_t>(2 * k + 1)]);
  }
  return flags;
}

// The nested lattice (LatticeGrading::nested): the fine nodes of the tensor lattice within the region's range on
// every axis, and the coarse nodes outside that closed box.
ParticleSet nested_lattice(const TissueBox& box, double h, const RegionOfInterest& roi) {
  std::vector<double> coarse[3], coarse_dual[3], coarse_spacing[3], fine[3], fine_dual[3], fine_spacing[3];
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    coarse[k] = axis_nodes(box.min_mm[k], box.max_mm[k], h, std::nullopt, 1);
    coarse_dual[k] = dual_lengths(coarse[k]);
    coarse_spacing[k] = local_spacing(coarse[k]);
    const double step = coarse[k][1] - coarse[k][0], tolerance = 1e-9 * step;
    // The region's range snapped outward to coarse nodes: the coarse intervals that overlap it.
    lo[k] = coarse[k].back();
    hi[k] = coarse[k].front();
    for (size_t i = 0; i + 1 < coarse[k].size(); ++i)
      if (coarse[k][i + 1] > roi.min_mm[k] + tolerance && coarse[k][i] < roi.max_mm[k] - tolerance) {
        lo[k] = std::min(lo[k], coarse[k][i]);
        hi[k] = std::max(hi[k], coarse[k][i + 1]);
      }
    for (double x : axis_nodes(box.min_mm[k], box.max_mm[k], h, std::array<double, 2>{roi.min_mm[k], roi.max_mm[k]}, roi.refinement))
      if (x >= lo[k] - tolerance && x <= hi[k] + tolerance) fine[k].push_back(x);
    fine_dual[k] = dual_lengths(fine[k]);
    fine_spacing[k] = local_spacing(fine[k]);
    // A face of the region inside the box: its fine nodes' cells reach half a coarse interval out (the coarse
    // cells there are gone with the coarse nodes on the face), and their nearest neighbour out is a coarse node.
    if (lo[k] > box.min_mm[k] + tolerance) {
      fine_dual[k].front() += 0.5 * step;
      fine_spacing[k].front() = std::max(fine_spacing[k].front(), step);
    }
    if (hi[k] < box.max_mm[k] - tolerance) {
      fine_dual[k].back() += 0.5 * step;
      fine_spacing[k].back() = std::max(fine_spacing[k].back(), step);
    }
  }
  const auto inside_region = [&](const Eigen::Vector3d& x) {
    for (int k = 0; k < 3; ++k) {
      const double tolerance = 1e-9 * h;
      if (x[k] < lo[k] - tolerance || x[k] > hi[k] + tolerance) return false;
    }
    return true;
  };
  std::vector<Eigen::Vector3d> x, axis_spacing;
  std::vector<double> volume;
  for (size_t a = 0; a < fine[0].size(); ++a)
    for (size_t b = 0; b < fine[1].size(); ++b)
      for (size_t c = 0; c < fine[2].size(); ++c) {
        x.emplace_back(fine[0][a], fine[1][b], fine[2][c]);
        volume.push_back(fine_dual[0][a] * fine_dual[1][b] * fine_dual[2][c]);
        axis_spacing.emplace_back(fine_spacing[0][a], fine_spacing[1][b], fine_spacing[2][c]);
      }
  for (size_t a = 0; a < coarse[0].size(); ++a)
    for (size_t b = 0; b < coarse[1].size(); ++b)
      for (size_t c = 0; c < coarse[2].size(); ++c) {
        const Eigen::Vector3d p(coarse[0][a], coarse[1][b], coarse[2][c]);
        if (inside_region(p)) continue;
        x.push_back(p);
        volume.push_back(coarse_dual[0][a] * coarse_dual[1][b] * coarse_dual[2][c]);
        axis_spacing.emplace_back(coarse_spacing[0][a], coarse_spacing[1][b], coarse_spacing[2][c]);
      }
  const Eigen::Index n = static_cast<Eigen::Index>(x.size());
  ParticleSet p;
  p.x_mm.resize(n, 3);
  p.volume_mm3.resize(n);
  p.spacing_mm.resize(n);
  p.axis_spacing_mm.resize(n, 3);
  p.flags.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const size_t s = static_cast<size_t>(i);
    p.x_mm.row(i) = x[s].transpose();
    p.volume_mm3[i] = volume[s];
    p.axis_spacing_mm.row(i) = axis_spacing[s].transpose();
    p.spacing_mm[i] = axis_spacing[s].maxCoeff();
    p.flags[i] = face_flags(box, x[s], 1e-9 * h);
  }
  return p;
}

}  // namespace

LatticeGrading lattice_grading_from_name(const std::string& name) {
  if (name == "tensor") return LatticeGrading::tensor;
  if (name == "nested") return LatticeGrading::nested;
  throw InputError(fmt::format("lattice grading '{}' is not one of tensor, nested", name));
}

std::string lattice_grading_name(LatticeGrading grading) { return grading == LatticeGrading::nested ? "nested" : "tensor"; }

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

double lattice_particle_bound(const Eigen::Vector3d& extent_mm, double spacing_mm, int refinement) {
  double bound = 1;
  for (int k = 0; k < 3; ++k) bound *= extent_mm[k] / spacing_mm * refinement + 1;
  return bound;
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
  const double estimate = lattice_particle_bound(box.max_mm - box.min_mm, h, refinement);
  NEEDLE_REQUIRE(estimate < kMaxLatticeParticles, fmt::format("spacing {} mm would make about {:.3g} particles (limit {:.0e})", h, estimate, kMaxLatticeParticles));

  if (options.region_of_interest && options.region_of_interest->grading == LatticeGrading::nested && refinement > 1)
    return nested_lattice(box, h, *options.region_of_interest);
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
