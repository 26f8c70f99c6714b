#pragma once
// What a needle designer compares needles by: the tip compliance (displacement of tip point A per
// newton of tip load, in y and in z) and the first bending frequencies, of the needle clamped at its
// base plane. The load is spread over the tip's facets in proportion to area (consistent nodal loads),
// so that no point singularity decides the answer; A's displacement is read at the mesh node at A.
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "solver/needle/fe_needle.h"

namespace needle {

// Consistent nodal weights (summing to 1) of a uniform traction on the boundary faces with these
// tags. InputError if no face carries any of the tags.
Eigen::VectorXd facet_load_weights(const TetMesh& mesh, const std::vector<std::string>& tags);

struct StiffnessResult {
  double compliance_y_mm_per_N = 0, compliance_z_mm_per_N = 0;
  double frequency_y_hz = 0, frequency_z_hz = 0;
  std::vector<double> mode_frequencies_hz;  // the lowest modes computed, with their direction
  std::vector<std::string> mode_directions;  // "y", "z", "axial" or "torsion/mixed"
  int tip_node = -1;
  double tip_node_offset_mm = 0;  // distance of that node from A
  double load_centroid_x_mm = 0;  // x of the load's resultant
  int clamped_nodes = 0, free_dofs = 0;
};

// Clamps every node on `clamp_tag` faces, loads the `load_tags` faces, solves and computes `modes`
// lowest modes (>= 2).
StiffnessResult analyse_stiffness(const FeNeedle& needle, const Eigen::Vector3d& tip_point_mm,
                                  const std::vector<std::string>& load_tags, const std::string& clamp_tag = "base",
                                  int modes = 4);

}  // namespace needle
