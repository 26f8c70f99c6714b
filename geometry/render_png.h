#pragma once
// A picture of the tip: the surface near the tip drawn from above and from below with a z-buffer,
// each facet in its own colour (tag_colors.h), with a legend. Written as PNG (all or nothing).
#include <string>

#include "geometry/tri_surface.h"
#include "plot/raster_image.h"

namespace needle {

struct RenderOptions {
  int panel_width_px = 900;
  int panel_height_px = 520;
  double view_from_x_mm = -4.0;  // draw only what lies at x >= this (the tip region)
  std::string title;
};

RgbImage render_tip_image(const TriSurface& surface, const RenderOptions& options);
void render_tip_png(const TriSurface& surface, const std::string& path, const RenderOptions& options);

}  // namespace needle
