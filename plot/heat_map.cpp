#include "plot/heat_map.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"

namespace needle {

Rgb heat_map_colour(double value, double centre, double half_range) {
  const double t = half_range > 0 ? std::clamp((value - centre) / half_range, -1.0, 1.0) : 0.0;
  const Rgb far = t < 0 ? Rgb{33, 102, 172} : Rgb{178, 24, 43};  // the ends of a blue-white-red scale
  const double a = std::abs(t);
  auto mix = [&](int k) { return static_cast<unsigned char>(std::lround(255 + (far[k] - 255) * a)); };
  return {mix(0), mix(1), mix(2)};
}

RgbImage draw_heat_map(const HeatMap& map) {
  NEEDLE_REQUIRE(!map.x.empty() && !map.y.empty() && map.values.size() == map.y.size(),
                 fmt::format("map '{}': {} rows of values for {} y values", map.title, map.values.size(), map.y.size()));
  double half_range = 0;
  bool any = false;
  for (const auto& row : map.values) {
    NEEDLE_REQUIRE(row.size() == map.x.size(), fmt::format("map '{}': a row of {} values for {} x values", map.title, row.size(), map.x.size()));
    for (double v : row)
      if (std::isfinite(v)) {
        any = true;
        half_range = std::max(half_range, std::abs(v - map.centre));
      }
  }
  NEEDLE_REQUIRE(any, fmt::format("map '{}' has no finite values", map.title));
  RgbImage image(map.width_px, map.height_px);
  TextWriter title(20), text(15), cell_text(13);
  const Rgb ink{30, 30, 30}, none{200, 200, 200};
  const int left = 110, right = 120, top = 50, bottom = 70;
  const int w = map.width_px - left - right, h = map.height_px - top - bottom;
  const int nx = static_cast<int>(map.x.size()), ny = static_cast<int>(map.y.size());
  title.draw(image, left, 32, map.title, ink);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int x0 = left + i * w / nx, x1 = left + (i + 1) * w / nx;
      const int y1 = top + h - j * h / ny, y0 = top + h - (j + 1) * h / ny;  // y grows upward
      const double v = map.values[static_cast<size_t>(j)][static_cast<size_t>(i)];
      const Rgb c = std::isfinite(v) ? heat_map_colour(v, map.centre, half_range) : none;
      image.fill_rect(x0 + 1, y0 + 1, x1 - 1, y1 - 1, c);
      const std::string label = std::isfinite(v) ? fmt::format(fmt::runtime(map.value_format), v) : "n/a";
      const bool dark = std::isfinite(v) && std::abs(v - map.centre) > 0.6 * half_range;
      cell_text.draw(image, (x0 + x1) / 2 - cell_text.width(label) / 2, (y0 + y1) / 2 + 5, label, dark ? Rgb{255, 255, 255} : ink);
    }
  for (int i = 0; i < nx; ++i) {
    const std::string label = fmt::format("{:g}", map.x[static_cast<size_t>(i)]);
    text.draw(image, left + (2 * i + 1) * w / (2 * nx) - text.width(label) / 2, top + h + 22, label, ink);
  }
  for (int j = 0; j < ny; ++j) {
    const std::string label = fmt::format("{:g}", map.y[static_cast<size_t>(j)]);
    text.draw(image, left - 8 - text.width(label), top + h - (2 * j + 1) * h / (2 * ny) + 5, label, ink);
  }
  text.draw(image, left + w / 2 - text.width(map.x_label) / 2, map.height_px - 20, map.x_label, ink);
  text.draw_vertical(image, 24, top + h / 2 + text.width(map.y_label) / 2, map.y_label, ink);
  // The colour bar: the centre in the middle, the largest distance from it at the ends.
  const int bar_x = left + w + 30, bar_w = 20;
  for (int k = 0; k < h; ++k) {
    const double v = map.centre + half_range * (1.0 - 2.0 * k / (h - 1));
    image.fill_rect(bar_x, top + k, bar_x + bar_w, top + k + 1, heat_map_colour(v, map.centre, half_range));
  }
  for (double t : {1.0, 0.0, -1.0}) {
    const std::string label = fmt::format(fmt::runtime(map.value_format), map.centre + t * half_range);
    text.draw(image, bar_x + bar_w + 6, top + static_cast<int>((1.0 - t) / 2 * (h - 1)) + 5, label, ink);
  }
  return image;
}

}  // namespace needle
