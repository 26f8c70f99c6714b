#pragma once
// A map of a value over a grid of two variables as PNG: one cell per (x, y) pair, coloured on a diverging scale
// (blue below the centre value, white at it, red above, the scale symmetric about it), the value printed in each
// cell, the variables' values along the axes and a colour bar. Cells without a finite value are left grey.
#include <string>
#include <vector>

#include "plot/raster_image.h"

namespace needle {

struct HeatMap {
  std::string title, x_label, y_label, value_format = "{:+.3f}";
  std::vector<double> x, y;                 // the grid's values along each axis, in order
  std::vector<std::vector<double>> values;  // values[j][i] at (x[i], y[j]); NaN: no value
  double centre = 0;                        // the value drawn white
  int width_px = 900, height_px = 600;
};

// The colour of a value on the map's scale (half_range: the largest distance of a value from the centre).
Rgb heat_map_colour(double value, double centre, double half_range);

// InputError if the grid is empty, its values' shape does not match, or no value is finite.
RgbImage draw_heat_map(const HeatMap& map);

}  // namespace needle
