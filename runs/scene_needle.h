#pragma once
// The needle a scene describes: meshed from a preset, d_a, recipe, plain rod (through build_needle)
// or a mesh file, with its tip point A; its dynamics options; its ParaView frames. Shared by
// `needle simulate` and `needle run`.
#include <Eigen/Dense>
#include <optional>
#include <string>
#include <vector>

#include "runs/scene.h"
#include "geometry/tip_geometry.h"
#include "mesher/tet_mesh.h"
#include "solver/needle/needle_dynamics.h"

namespace needle {

struct SceneNeedle {
  std::string name;
  TetMesh mesh;
  Eigen::Vector3d tip_point = Eigen::Vector3d::Zero();  // A (for a mesh file: its most distal node)
  std::optional<GrooveBox> groove;  // in the mesh's frame (absent for a mesh file or a groove-less tip)
  double radius_mm = 0.5;
  std::vector<std::string> tip_facets;  // boundary tags of the tip's ground facets (none for a plain rod or a mesh file)
  double mesh_seconds = 0;
};

SceneNeedle build_scene_needle(const NeedleScene& needle);

// The FE needle's step and stop criteria from the scene's solver section.
NeedleDynamicsOptions scene_dynamics_options(const Scene& scene);

// The deformed needle as a .vtu: displacement and velocity (points), von Mises and Cauchy stress (tets).
void write_needle_vtu(const std::string& path, const NeedleModel& run);

}  // namespace needle
