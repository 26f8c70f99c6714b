#pragma once
// The rigid, fixed cannula that supports the needle (paper: OD 1.27 mm, wall 0.05 mm, 18 G): a tube
// along the x axis from front_x_mm - length_mm to front_x_mm. Needle surface nodes inside its length
// that pass its inner radius are pushed back by a penalty force along the radius, with Coulomb
// friction on their sliding velocity.
//   normal:   f_n = k_i p,  p = r - r_inner > 0,  k_i = penalty_scale m_i / dt^2
//   friction: f_t = -min(mu f_n, c_i |v_t|) v_t / |v_t|,  c_i = m_i / (2 dt)
// Both scale with the node's mass and the step, so contact never limits the stable step; the
// viscous cap regularises sticking (a node at rest feels no friction).
#include <Eigen/Dense>
#include <string>
#include <vector>

namespace needle {

struct CannulaOptions {
  bool enabled = true;
  double outer_diameter_mm = 1.27;
  double wall_mm = 0.05;
  double front_x_mm = 0.0;     // where the cannula ends (the tissue's entry face in the paper scene)
  double length_mm = 40.0;
  double friction = 0.18;      // needle-cannula Coulomb coefficient (the paper gives only needle-tissue)
  double penalty_scale = 0.1;  // k_i = scale m_i / dt^2

  double inner_radius_mm() const { return 0.5 * outer_diameter_mm - wall_mm; }
  void validate(const std::string& where = "cannula") const;
};

struct CannulaContact {
  int nodes_in_contact = 0;
  double max_penetration_mm = 0;
  double normal_force_N = 0;     // sum of |f_n|
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();  // total force on the needle
};

class RigidCannula {
 public:
  // candidate_nodes: the needle's surface nodes; mass_g: all nodal masses; dt_ms: the step it runs at.
  RigidCannula(const CannulaOptions& options, std::vector<int> candidate_nodes, const Eigen::VectorXd& mass_g, double dt_ms);

  // Adds the contact forces at positions x and velocities v to force (all #nodes x 3).
  CannulaContact add_forces(const Eigen::MatrixX3d& x_mm, const Eigen::MatrixX3d& v_mm_per_ms, Eigen::MatrixX3d& force_N) const;
  const CannulaOptions& options() const { return options_; }

 private:
  CannulaOptions options_;
  std::vector<int> nodes_;
  std::vector<double> stiffness_, damping_;
};

}  // namespace needle
