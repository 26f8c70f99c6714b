#include "geometry/surface_measures.h"

#include <fmt/format.h>
#include <map>
#include <tuple>
#include <unordered_map>

namespace needle {

int TriSurface::tag_index(const std::string& name) const {
  for (size_t i = 0; i < tag_names.size(); ++i)
    if (tag_names[i] == name) return static_cast<int>(i);
  return -1;
}

std::string TopologyCheck::describe() const {
  return fmt::format("{} boundary edges, {} non-manifold edges, {} inconsistently oriented edges, "
                     "{} degenerate triangles",
                     boundary_edges, non_manifold_edges, inconsistent_edges, degenerate_faces);
}

TopologyCheck check_topology(const TriSurface& surface) {
  TopologyCheck check;
  // Count directed edges per undirected edge.
  struct Count { int forward = 0, backward = 0; };
  std::unordered_map<uint64_t, Count> edges;
  edges.reserve(surface.num_faces() * 2);
  for (int f = 0; f < surface.num_faces(); ++f) {
    const int a = surface.F(f, 0), b = surface.F(f, 1), c = surface.F(f, 2);
    if (a == b || b == c || a == c) {
      ++check.degenerate_faces;
      continue;
    }
    for (auto [u, v] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      const uint64_t key = (static_cast<uint64_t>(std::min(u, v)) << 32) | static_cast<uint32_t>(std::max(u, v));
      Count& count = edges[key];
      (u < v ? count.forward : count.backward)++;
    }
  }
  for (const auto& [key, count] : edges) {
    const int total = count.forward + count.backward;
    if (total == 1) ++check.boundary_edges;
    else if (total > 2) ++check.non_manifold_edges;
    else if (count.forward != 1) ++check.inconsistent_edges;
  }
  return check;
}

namespace {
Eigen::Vector3d corner(const TriSurface& s, int f, int k) { return s.V.row(s.F(f, k)).transpose(); }
double triangle_area(const TriSurface& s, int f) {
  return 0.5 * (corner(s, f, 1) - corner(s, f, 0)).cross(corner(s, f, 2) - corner(s, f, 0)).norm();
}
}  // namespace

double surface_area_mm2(const TriSurface& surface) {
  double area = 0;
  for (int f = 0; f < surface.num_faces(); ++f) area += triangle_area(surface, f);
  return area;
}

std::vector<double> area_by_tag_mm2(const TriSurface& surface) {
  std::vector<double> area(surface.tag_names.size(), 0.0);
  for (int f = 0; f < surface.num_faces(); ++f) area.at(surface.face_tag(f)) += triangle_area(surface, f);
  return area;
}

double enclosed_volume_mm3(const TriSurface& surface) {
  // Signed tetrahedra against a reference point near the surface keep the sum well conditioned.
  const Eigen::Vector3d origin = surface.V.colwise().mean().transpose();
  double six_volume = 0;
  for (int f = 0; f < surface.num_faces(); ++f)
    six_volume += (corner(surface, f, 0) - origin)
                      .dot((corner(surface, f, 1) - origin).cross(corner(surface, f, 2) - origin));
  return six_volume / 6.0;
}

Eigen::Vector3d most_distal_point(const TriSurface& surface) {
  Eigen::Index best = 0;
  surface.V.col(0).maxCoeff(&best);
  return surface.V.row(best).transpose();
}

double min_x_of_tags(const TriSurface& surface, const std::vector<int>& tags) {
  double min_x = std::numeric_limits<double>::infinity();
  for (int f = 0; f < surface.num_faces(); ++f)
    if (std::find(tags.begin(), tags.end(), surface.face_tag(f)) != tags.end())
      for (int k = 0; k < 3; ++k) min_x = std::min(min_x, surface.V(surface.F(f, k), 0));
  return min_x;
}

TriSurface weld_identical_vertices(const TriSurface& surface) {
  std::map<std::tuple<double, double, double>, int> index;
  std::vector<int> remap(surface.num_vertices());
  std::vector<Eigen::Vector3d> kept;
  for (int f = 0; f < surface.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int v = surface.F(f, k);
      const auto key = std::make_tuple(surface.V(v, 0), surface.V(v, 1), surface.V(v, 2));
      auto [it, inserted] = index.emplace(key, static_cast<int>(kept.size()));
      if (inserted) kept.push_back(surface.V.row(v).transpose());
      remap[v] = it->second;
    }
  TriSurface welded;
  welded.V.resize(kept.size(), 3);
  for (size_t i = 0; i < kept.size(); ++i) welded.V.row(i) = kept[i].transpose();
  // Triangles whose corners merged (slivers thinner than double precision) are dropped.
  std::vector<int> kept_faces;
  for (int f = 0; f < surface.num_faces(); ++f) {
    const int a = remap[surface.F(f, 0)], b = remap[surface.F(f, 1)], c = remap[surface.F(f, 2)];
    if (a != b && b != c && a != c) kept_faces.push_back(f);
  }
  welded.F.resize(kept_faces.size(), 3);
  welded.face_tag.resize(kept_faces.size());
  for (size_t i = 0; i < kept_faces.size(); ++i) {
    for (int k = 0; k < 3; ++k) welded.F(i, k) = remap[surface.F(kept_faces[i], k)];
    if (surface.face_tag.size() == surface.num_faces()) welded.face_tag(i) = surface.face_tag(kept_faces[i]);
  }
  welded.tag_names = surface.tag_names;
  return welded;
}

}  // namespace needle
