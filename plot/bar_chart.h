#pragma once
// Grouped bar charts as PNG: one group of bars per category (a needle), one bar per series (ours,
// experiment, LS-DYNA), a zero line, the value printed on each bar, a legend below the axes. A bar may
// carry a range, drawn as a whisker through it (e.g. the run-to-run spread of a simulated value).
#include <string>
#include <utility>
#include <vector>

#include "plot/raster_image.h"

namespace needle {

struct BarSeries {
  BarSeries() = default;
  BarSeries(std::string label_, std::vector<double> values_, Rgb color_ = {31, 119, 180},
            std::vector<std::pair<double, double>> ranges_ = {})
      : label(std::move(label_)), values(std::move(values_)), color(color_), ranges(std::move(ranges_)) {}

  std::string label;
  std::vector<double> values;  // one per category; NaN: no bar
  Rgb color{31, 119, 180};
  // Optional, one per category: {low, high} drawn as a whisker through the bar; a NaN end: none.
  std::vector<std::pair<double, double>> ranges;
};

struct BarChart {
  std::string title, y_label;
  std::vector<std::string> categories;
  std::vector<BarSeries> series;
  std::string value_format = "{:+.2f}";
  int width_px = 900, height_px = 600;  // the width grows where the value labels would not fit their bars
  std::string range_label;                // the whiskers' legend entry, shown when a whisker is drawn
  Rgb range_color{30, 30, 30};
};

// InputError if no bar has a finite value.
RgbImage draw_bar_chart(const BarChart& chart);

}  // namespace needle
