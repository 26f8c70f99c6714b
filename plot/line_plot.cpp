#include "plot/line_plot.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"
#include "plot/axis_ticks.h"

namespace needle {

Rgb plot_color(int index) {
  static const Rgb palette[] = {{31, 119, 180}, {214, 39, 40}, {44, 160, 44}, {255, 127, 14},
                                {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127}};
  return palette[static_cast<size_t>(index) % 8];
}

RgbImage draw_line_plot(const LinePlot& plot) {
  double x_min = 1e300, x_max = -1e300, y_min = 1e300, y_max = -1e300;
  for (const PlotSeries& s : plot.series)
    for (size_t k = 0; k < std::min(s.x.size(), s.y.size()); ++k) {
      if (!std::isfinite(s.x[k]) || !std::isfinite(s.y[k])) continue;
      x_min = std::min(x_min, s.x[k]), x_max = std::max(x_max, s.x[k]);
      y_min = std::min(y_min, s.y[k]), y_max = std::max(y_max, s.y[k]);
    }
  NEEDLE_REQUIRE(x_min <= x_max, fmt::format("plot '{}' has no finite points", plot.title));
  // Values within round-off of zero do not pull an axis below (or above) zero.
  if (y_min < 0 && y_min > -1e-9 * std::abs(y_max)) y_min = 0;
  if (x_min < 0 && x_min > -1e-9 * std::abs(x_max)) x_min = 0;
  if (x_max - x_min < 1e-300) x_min -= 0.5, x_max += 0.5;
  if (y_max - y_min < 1e-300) y_min -= 0.5, y_max += 0.5;
  const double x_step = nice_tick_step(x_max - x_min, 8), y_step = nice_tick_step(y_max - y_min, 6);
  x_min = std::floor(x_min / x_step) * x_step, x_max = std::ceil(x_max / x_step) * x_step;
  y_min = std::floor(y_min / y_step) * y_step, y_max = std::ceil(y_max / y_step) * y_step;

  RgbImage image(plot.width_px, plot.height_px);
  TextWriter title(20), text(15);
  const Rgb ink{30, 30, 30}, grid{225, 225, 225};
  const int left = 90, right = 20, top = 50, bottom = 70;
  const int w = plot.width_px - left - right, h = plot.height_px - top - bottom;
  auto px = [&](double x) { return left + (x - x_min) / (x_max - x_min) * w; };
  auto py = [&](double y) { return top + h - (y - y_min) / (y_max - y_min) * h; };

  title.draw(image, left, 32, plot.title, ink);
  for (double x = x_min; x <= x_max + 1e-9 * x_step; x += x_step) {
    image.line(px(x), top, px(x), top + h, grid, 1.0);
    const std::string label = tick_label(x, x_step);
    text.draw(image, static_cast<int>(px(x)) - text.width(label) / 2, top + h + 20, label, ink);
  }
  for (double y = y_min; y <= y_max + 1e-9 * y_step; y += y_step) {
    image.line(left, py(y), left + w, py(y), grid, 1.0);
    const std::string label = tick_label(y, y_step);
    text.draw(image, left - 8 - text.width(label), static_cast<int>(py(y)) + 5, label, ink);
  }
  image.line(left, top, left, top + h, ink, 1.2);
  image.line(left, top + h, left + w, top + h, ink, 1.2);
  text.draw(image, left + w / 2 - text.width(plot.x_label) / 2, plot.height_px - 20, plot.x_label, ink);
  text.draw_vertical(image, 24, top + h / 2 + text.width(plot.y_label) / 2, plot.y_label, ink);

  for (const PlotSeries& s : plot.series) {
    const size_t n = std::min(s.x.size(), s.y.size());
    for (size_t k = 1; s.line && k < n; ++k)
      if (std::isfinite(s.x[k - 1] + s.y[k - 1] + s.x[k] + s.y[k]))
        image.line(px(s.x[k - 1]), py(s.y[k - 1]), px(s.x[k]), py(s.y[k]), s.color, 2.0, s.dashed ? 8.0 : 0.0);
    if (s.markers)
      for (size_t k = 0; k < n; ++k)
        if (std::isfinite(s.x[k] + s.y[k]))
          for (int a = 0; a < 16; ++a)
            image.line(px(s.x[k]) + 4 * std::cos(a * M_PI / 8), py(s.y[k]) + 4 * std::sin(a * M_PI / 8),
                       px(s.x[k]) + 4 * std::cos((a + 1) * M_PI / 8), py(s.y[k]) + 4 * std::sin((a + 1) * M_PI / 8), s.color, 1.5);
  }
  // Legend, top left inside the axes.
  int y = top + 22;
  for (const PlotSeries& s : plot.series) {
    if (s.label.empty()) continue;
    if (s.line) image.line(left + 14, y - 5, left + 44, y - 5, s.color, 2.5, s.dashed ? 6.0 : 0.0);
    if (!s.line || s.markers)
      for (int a = 0; a < 16; ++a)
        image.line(left + 29 + 4 * std::cos(a * M_PI / 8), y - 5 + 4 * std::sin(a * M_PI / 8), left + 29 + 4 * std::cos((a + 1) * M_PI / 8),
                   y - 5 + 4 * std::sin((a + 1) * M_PI / 8), s.color, 1.5);
    text.draw(image, left + 52, y, s.label, ink);
    y += 22;
  }
  return image;
}

}  // namespace needle
