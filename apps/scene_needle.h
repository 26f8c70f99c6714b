#pragma once
// The needle a scene describes, meshed: from a preset, d_a, recipe, plain rod (through build_needle)
// or a mesh file, with its tip point A. Shared by `needle simulate` and `needle run`.
#include <Eigen/Dense>
#include <string>

#include "apps/scene.h"
#include "mesher/tet_mesh.h"

namespace needle {

struct SceneNeedle {
  std::string name;
  TetMesh mesh;
  Eigen::Vector3d tip_point = Eigen::Vector3d::Zero();  // A (for a mesh file: its most distal node)
  double mesh_seconds = 0;
};

SceneNeedle build_scene_needle(const NeedleScene& needle);

}  // namespace needle
