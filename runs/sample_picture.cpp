#include "runs/sample_picture.h"

#include <cmath>
#include <fmt/format.h>

#include "plot/line_plot.h"

namespace needle {

RgbImage draw_sample_picture(const SamplePictureInput& in) {
  constexpr double kNearPlaneMm = 0.3;  // the tissue left outside is drawn within this of the symmetry plane
  const GrooveBox& g = in.groove;
  PlotSeries on_floor{"sample resting on the floor (I_s: the floor under it)", {}, {}, {214, 39, 40}, false, true, false};
  PlotSeries captured{"sample", {}, {}, {255, 127, 14}, false, true, false};
  PlotSeries outside{"tissue left outside (|z| < 0.3 mm)", {}, {}, {170, 170, 170}, false, true, false};
  for (size_t i = 0; i < in.reference_points.size(); ++i) {
    const Eigen::Vector3d& X = in.reference_points[i];
    if (!X.allFinite() || X.x() < g.back_x_mm - 1 || X.x() > g.front_x_mm + 1 || std::abs(X.y()) > 1.5) continue;
    if (in.sample.captured[i]) {
      PlotSeries& s = in.sample.in_floor_layer[i] ? on_floor : captured;
      s.x.push_back(X.x());
      s.y.push_back(X.y());
    } else if (std::abs(X.z()) < kNearPlaneMm) {
      outside.x.push_back(X.x());
      outside.y.push_back(X.y());
    }
  }
  const double lo = g.back_x_mm - 1, hi = g.front_x_mm + 1;
  LinePlot plot;
  plot.title = fmt::format("The sample: I_s {:.2f} mm (the floor it rests on), {:.2f} mm in all, {:.3f} mm3", in.sample.I_s_mm(),
                           in.sample.length_mm, in.sample.volume_mm3);
  plot.x_label = "x along the needle (mm; tip point A at 0)";
  plot.y_label = "y (mm)";
  plot.width_px = 1400;
  plot.height_px = 500;
  plot.series.push_back(outside);
  plot.series.push_back(captured);
  plot.series.push_back(on_floor);
  plot.series.push_back({"groove floor", {g.back_x_mm, g.front_x_mm}, {g.floor_y_mm, g.floor_y_mm}, {0, 0, 0}});
  plot.series.push_back({"rod's top", {lo, g.back_x_mm, g.back_x_mm, g.front_x_mm, g.front_x_mm, hi},
                         {in.rod_radius_mm, in.rod_radius_mm, g.floor_y_mm, g.floor_y_mm, in.rod_radius_mm, in.rod_radius_mm}, {90, 90, 90}, true});
  plot.series.push_back({"cannula's bore", {lo, hi}, {in.tube.inner_radius_mm, in.tube.inner_radius_mm}, {31, 119, 180}, true});
  return draw_line_plot(plot);
}

}  // namespace needle
