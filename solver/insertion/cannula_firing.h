#pragma once
// The trucut's third step (issue 50): after the needle's travel the outer cannula is fired over it, and its edge cuts
// off the tissue lying in the groove. The cannula is a rigid tube that follows the needle's deflected axis: in the
// needle's reference frame (solver/needle/needle_axis_frame.h) it is a straight tube around the x axis, of the scene's
// cannula's bore and outer radius, whose front moves along x at the firing's speed. It acts on the tissue only:
//   - its edge cuts every intact bond whose segment crosses the tube's mid-wall cylinder r = (r_in + r_out) / 2
//     between where the stroke starts and the front (exactly: the segment's roots on the cylinder), after each step,
//     through the separation seam (solver/separation/cannula_edge_cut.h);
//   - its wall pushes the tissue out of itself: between the tissue's two halves of a step, a particle behind the
//     front whose end position lies inside the wall gets the impulse that puts it on the nearer face (inside the mid
//     radius the bore's, outside it the outer face), its radial velocity changed by as much (a kinematic,
//     frictionless contact; its work is booked as an input of the run's energy account). The edge is bevelled: the
//     wall grows from the mid radius at the front to its full thickness edge_taper_mm behind it, so the front parts
//     the tissue over several steps instead of moving a particle by half the wall in one.
// The needle feels neither: the cannula rides over it without loading it (its bore clears the rod), and the needle's
// own support is the scene's fixed cannula (rigid_cannula.h). The part of the stroke over the solid rod behind the
// groove, where the bore holds nothing but the clearance's layer of tissue, is not simulated: the front starts
// lead_in_mm behind the groove's back wall, as if it had come from the cannula's rest position at the firing's speed.
#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "solver/needle/needle_axis_frame.h"
#include "solver/tissue/bond_network.h"
#include "solver/tissue/tissue_dynamics.h"

namespace needle {

struct CannulaFiringOptions {
  bool enabled = false;              // off: the insertion alone (today's runs, bit for bit)
  double speed_mm_per_ms = 4.0;      // the paper's device: about 4 m/s
  double throw_mm = std::nan("");    // from the cannula's front at rest; NaN: to the groove's far end (its front wall)
  double dwell_ms = 0.0;             // the pause between the needle's travel (and hold) and the firing
  double lead_in_mm = 1.0;           // the stroke is simulated from this far behind the groove's back wall
  double edge_taper_mm = 0.2;        // the edge's bevel: the wall's full thickness this far behind the front
  // The tissue's mass scaling target from the firing on, where the run scales it (0: kMassScalingGrowth times the
  // insertion's, twice the implicit needle's step). The insertion's target, half the implicit needle's step, is for the
  // needle's coupling; the held needle takes none, and the stroke is longer than the insertion (its effect on the sample
  // is measured in docs/notebook/sampling.md and multirate.md).
  double tissue_mass_scaling_dt_ms = 0.0;
  static constexpr double kMassScalingGrowth = 4.0;
  void validate(const std::string& where = "cannula.firing") const;  // InputError naming the bad field
  // The firing in a run's one-line description; empty when off.
  std::string describe() const;
};

// The tube's section: the scene cannula's bore and outer radius, and its edge's bevel; the rod it rides over.
struct CannulaTube {
  double inner_radius_mm = 0.585, outer_radius_mm = 0.635, edge_taper_mm = 0.2;
  double rod_radius_mm = 0.5;
  double mid_radius_mm() const { return 0.5 * (inner_radius_mm + outer_radius_mm); }
};

// The front in the needle's reference frame: at start_x_mm until start_time_ms, then moving at the speed to stop_x_mm.
struct CannulaStroke {
  double start_time_ms = 0, start_x_mm = 0, stop_x_mm = 0, speed_mm_per_ms = 4.0;
  double front_x_mm(double time_ms) const;
  double end_time_ms() const { return start_time_ms + (stop_x_mm - start_x_mm) / speed_mm_per_ms; }
};

class CannulaFiring {
 public:
  // frame: the needle's (the world's for a tube fired through tissue alone).
  CannulaFiring(const CannulaTube& tube, const CannulaStroke& stroke, NeedleAxisFrame frame);

  const CannulaTube& tube() const { return tube_; }
  const CannulaStroke& stroke() const { return stroke_; }
  bool active(double time_ms) const { return time_ms > stroke_.start_time_ms; }
  // How far beyond the rod's surface the cannula acts on the tissue (the coupled step's margins around the needle's box
  // must reach as far).
  double reach_beyond_rod_mm() const { return tube_.outer_radius_mm - tube_.rod_radius_mm; }

  // The particles at x carried into the needle's reference frame, with the needle's nodes at needle_x (empty for the
  // world's frame).
  std::vector<Eigen::Vector3d> reference_points(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x) const;
  // The wall's impulses between the tissue's halves of the step of dt_ms that ends at time_ms (see above).
  void push_tissue(TissueDynamics& tissue, const Eigen::MatrixX3d& needle_x, double time_ms, double dt_ms);
  // The intact bonds whose segment crosses the mid-wall cylinder between the stroke's start and the front at
  // time_ms, in increasing order.
  std::vector<std::int64_t> bonds_across(const BondNetwork& bonds, const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x,
                                         double time_ms) const;
  // Per particle: 1 inside the mid-wall cylinder between the stroke's start and the front at time_ms.
  std::vector<std::uint8_t> inside_bore(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x, double time_ms) const;

  double work_mJ() const { return work_mJ_; }          // the wall's work on the tissue
  std::int64_t pushes() const { return pushes_; }      // particle impulses so far
  double max_push_mm() const { return max_push_mm_; }  // the largest radial correction of one

 private:
  // The wall's faces at reference x (the bevel narrows them toward the mid radius at the front).
  void faces_at(double x_mm, double front_x_mm, double& inner_mm, double& outer_mm) const;

  CannulaTube tube_;
  CannulaStroke stroke_;
  mutable NeedleAxisFrame frame_;  // holds the needle's last positions given (a cache of the call, not state)
  double work_mJ_ = 0, max_push_mm_ = 0;
  std::int64_t pushes_ = 0;
};

}  // namespace needle
