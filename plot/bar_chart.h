#pragma once
// Grouped bar charts as PNG: one group of bars per category (a needle), one bar per series (ours,
// experiment, LS-DYNA), a zero line, the value printed on each bar, a legend below the axes.
#include <string>
#include <vector>

#include "plot/raster_image.h"

namespace needle {

struct BarSeries {
  std::string label;
  std::vector<double> values;  // one per category; NaN: no bar
  Rgb color{31, 119, 180};
};

struct BarChart {
  std::string title, y_label;
  std::vector<std::string> categories;
  std::vector<BarSeries> series;
  std::string value_format = "{:+.2f}";
  int width_px = 900, height_px = 600;  // the width grows where the value labels would not fit their bars
};

// InputError if no bar has a finite value.
RgbImage draw_bar_chart(const BarChart& chart);

}  // namespace needle
