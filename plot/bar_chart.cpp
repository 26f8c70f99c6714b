#include "plot/bar_chart.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <utility>
#include <vector>

#include "core/input_error.h"
#include "plot/axis_ticks.h"

namespace needle {

namespace {

constexpr int kLegendRowPx = 22;

// The range of series s's bar in category c, or nullptr where it has none.
const std::pair<double, double>* bar_range(const BarSeries& s, size_t c) {
  if (c >= s.ranges.size()) return nullptr;
  const std::pair<double, double>& r = s.ranges[c];
  return std::isfinite(r.first) && std::isfinite(r.second) ? &r : nullptr;
}

// The legend's entries: one per series, then the whiskers' where the chart draws one.
std::vector<std::string> legend_labels(const BarChart& chart) {
  std::vector<std::string> labels;
  bool any_range = false;
  for (const BarSeries& s : chart.series) {
    labels.push_back(s.label);
    for (size_t c = 0; c < chart.categories.size(); ++c) any_range = any_range || bar_range(s, c);
  }
  if (any_range && !chart.range_label.empty()) labels.push_back(chart.range_label);
  return labels;
}

// Where each legend entry goes: rows as wide as the axes under the category names. {x, row} per
// entry.
std::vector<std::pair<int, int>> legend_layout(TextWriter& text, const std::vector<std::string>& labels, int left, int right_edge) {
  std::vector<std::pair<int, int>> at;
  int x = left, row = 0;
  for (const std::string& label : labels) {
    const int entry = 24 + text.width(label) + 28;  // swatch, label, gap to the next
    if (x > left && x + entry > right_edge) x = left, ++row;
    at.emplace_back(x, row);
    x += entry;
  }
  return at;
}

}  // namespace

RgbImage draw_bar_chart(const BarChart& chart) {
  double y_min = 0, y_max = 0;  // bars start at zero, so zero is always on the axis
  bool any = false;
  for (const BarSeries& s : chart.series) {
    for (double v : s.values)
      if (std::isfinite(v)) y_min = std::min(y_min, v), y_max = std::max(y_max, v), any = true;
    for (size_t c = 0; c < s.values.size(); ++c)
      if (const auto* r = bar_range(s, c); r && std::isfinite(s.values[c]))
        y_min = std::min({y_min, r->first, r->second}), y_max = std::max({y_max, r->first, r->second});
  }
  NEEDLE_REQUIRE(any, fmt::format("bar chart '{}' has no finite values", chart.title));
  if (y_max - y_min < 1e-300) y_max += 1;
  const double step = nice_tick_step(y_max - y_min, 6);
  y_min = std::floor(y_min / step) * step, y_max = std::ceil(y_max / step) * step;
  if (y_max - y_min < 1.5 * step) y_max += step;  // room for the value labels

  TextWriter title(20), text(15), small(13);
  const Rgb ink{30, 30, 30}, grid{225, 225, 225};
  const int left = 90, right = 20, top = 50, bottom = 60;
  const int categories = static_cast<int>(chart.categories.size());
  const int bars = static_cast<int>(chart.series.size());
  // Every bar at least as wide as the widest value label (and a gap), so that the labels of
  // neighbouring bars never overlap: many series widen the chart instead.
  int widest_label = 0;
  for (const BarSeries& s : chart.series)
    for (double v : s.values)
      if (std::isfinite(v)) widest_label = std::max(widest_label, small.width(fmt::format(fmt::runtime(chart.value_format), v)));
  const int bars_width = static_cast<int>(std::ceil(std::max(1, categories) * std::max(1, bars) * (widest_label + 6) / 0.8));
  const int width_px = std::max(chart.width_px, left + right + bars_width);
  const std::vector<std::string> legend_text = legend_labels(chart);
  const std::vector<std::pair<int, int>> legend = legend_layout(text, legend_text, left, width_px - right);
  const int legend_rows = legend.empty() ? 0 : legend.back().second + 1;
  RgbImage image(width_px, chart.height_px + legend_rows * kLegendRowPx);
  const int w = width_px - left - right, h = chart.height_px - top - bottom;
  auto py = [&](double y) { return top + h - (y - y_min) / (y_max - y_min) * h; };
  title.draw(image, left, 32, chart.title, ink);
  for (double y = y_min; y <= y_max + 1e-9 * step; y += step) {
    image.line(left, py(y), left + w, py(y), grid, 1.0);
    const std::string label = tick_label(y, step);
    text.draw(image, left - 8 - text.width(label), static_cast<int>(py(y)) + 5, label, ink);
  }
  text.draw_vertical(image, 24, top + h / 2 + text.width(chart.y_label) / 2, chart.y_label, ink);
  const double group = static_cast<double>(w) / std::max(1, categories);
  const double bar = 0.8 * group / std::max(1, bars);
  for (int c = 0; c < categories; ++c) {
    const double group_left = left + c * group + 0.1 * group;
    const std::string& name = chart.categories[static_cast<size_t>(c)];
    text.draw(image, static_cast<int>(left + (c + 0.5) * group) - text.width(name) / 2, top + h + 24, name, ink);
    for (int b = 0; b < bars; ++b) {
      const BarSeries& s = chart.series[static_cast<size_t>(b)];
      if (static_cast<size_t>(c) >= s.values.size() || !std::isfinite(s.values[static_cast<size_t>(c)])) continue;
      const double v = s.values[static_cast<size_t>(c)];
      const int x0 = static_cast<int>(group_left + b * bar + 1), x1 = static_cast<int>(group_left + (b + 1) * bar - 1);
      const int y0 = static_cast<int>(std::min(py(v), py(0))), y1 = static_cast<int>(std::max(py(v), py(0)));
      image.fill_rect(x0, y0, x1, std::max(y1, y0 + 1), s.color);
      // The whisker: a 2 px stem from low to high through the bar's middle, capped at both ends.
      int top_px = y0, bottom_px = y1;
      if (const auto* r = bar_range(s, static_cast<size_t>(c))) {
        const int mid = (x0 + x1) / 2, cap = std::max(2, (x1 - x0) / 5);
        const int hi = static_cast<int>(py(std::max(r->first, r->second))), lo = static_cast<int>(py(std::min(r->first, r->second)));
        image.fill_rect(mid - 1, hi, mid + 1, lo, chart.range_color);
        image.fill_rect(mid - cap, hi - 1, mid + cap, hi + 1, chart.range_color);
        image.fill_rect(mid - cap, lo - 1, mid + cap, lo + 1, chart.range_color);
        top_px = std::min(top_px, hi - 1), bottom_px = std::max(bottom_px, lo + 1);
      }
      const std::string label = fmt::format(fmt::runtime(chart.value_format), v);
      const int label_y = v >= 0 ? top_px - 4 : bottom_px + 15;
      small.draw(image, (x0 + x1) / 2 - small.width(label) / 2, label_y, label, ink);
    }
  }
  image.line(left, top, left, top + h, ink, 1.2);
  image.line(left, py(0), left + w, py(0), ink, 1.2);
  // Legend under the category names: never over a bar.
  for (size_t k = 0; k < legend.size(); ++k) {
    const auto [x, row] = legend[k];
    const int y = chart.height_px + 8 + row * kLegendRowPx;
    if (k < chart.series.size()) {
      image.fill_rect(x, y - 12, x + 16, y + 2, chart.series[k].color);
    } else {  // the whiskers' entry: a small capped stem
      image.fill_rect(x + 7, y - 12, x + 9, y + 2, chart.range_color);
      image.fill_rect(x + 3, y - 13, x + 13, y - 11, chart.range_color);
      image.fill_rect(x + 3, y + 1, x + 13, y + 3, chart.range_color);
    }
    text.draw(image, x + 24, y, legend_text[k], ink);
  }
  return image;
}

}  // namespace needle
