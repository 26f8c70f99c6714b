#pragma once
// A closed triangle surface whose every triangle carries the tag of the CAD facet that made it.
#include <Eigen/Dense>
#include <string>
#include <vector>

namespace needle {

struct TriSurface {
  Eigen::MatrixX3d V;              // #V by 3 vertex positions, mm
  Eigen::MatrixX3i F;              // #F by 3 vertex indices, counter-clockwise seen from outside
  Eigen::VectorXi face_tag;        // #F tag index into tag_names
  std::vector<std::string> tag_names;

  int num_faces() const { return static_cast<int>(F.rows()); }
  int num_vertices() const { return static_cast<int>(V.rows()); }
  int tag_index(const std::string& name) const;  // -1 if absent
};

}  // namespace needle
