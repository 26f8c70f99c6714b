#pragma once
// Line charts as PNG: x-y series with a legend, axis labels and tick values chosen 1-2-5.
#include <string>
#include <vector>

#include "plot/raster_image.h"

namespace needle {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;
  Rgb color{31, 119, 180};
  bool dashed = false;
  bool markers = false;  // small circles at the points
  bool line = true;      // false: the points alone (measured values, reference points)
};

struct LinePlot {
  std::string title, x_label, y_label;
  std::vector<PlotSeries> series;
  int width_px = 900, height_px = 600;
};

// Draws the plot; InputError if there is nothing finite to draw. Write it with write_png (inside
// write_file_atomically for an all-or-nothing file).
RgbImage draw_line_plot(const LinePlot& plot);

// Colours for successive series.
Rgb plot_color(int index);

}  // namespace needle
