#pragma once
// The picture of a fired cannula's sample (issue 50): the groove seen from the side in the needle's reference frame
// (x along the axis, tip point A at 0; y up), the captured particles (those that touched the groove floor apart), the
// tissue left outside near the symmetry plane, the groove's floor, the rod's top and the cannula's bore. A run with a
// fired cannula writes it as sample.png.
#include <Eigen/Dense>
#include <cstdint>
#include <vector>

#include "geometry/tip_geometry.h"
#include "plot/raster_image.h"
#include "solver/insertion/cannula_firing.h"
#include "solver/insertion/tissue_sample.h"

namespace needle {

struct SamplePictureInput {
  std::vector<Eigen::Vector3d> reference_points;  // per particle, in the needle's reference frame
  TissueSample sample;
  GrooveBox groove;
  double rod_radius_mm = 0.5;
  CannulaTube tube;
};

RgbImage draw_sample_picture(const SamplePictureInput& input);

}  // namespace needle
