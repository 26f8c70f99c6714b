// Maps over two variables (plot/heat_map.h): the colour scale's ends and centre, and each cell drawn in its value's colour
// at its place on the grid (y upward).
#include <catch2/catch.hpp>
#include <cmath>

#include "core/input_error.h"
#include "plot/heat_map.h"

using namespace needle;

namespace {
Rgb pixel(const RgbImage& image, int x, int y) {
  const size_t p = 3 * (static_cast<size_t>(y) * image.width + x);
  return {image.rgb[p], image.rgb[p + 1], image.rgb[p + 2]};
}
}  // namespace

TEST_CASE("A heat map's cells take their values' colours on a scale white at its centre", "[plot]") {
  CHECK(heat_map_colour(0.3, 0.3, 1.0) == Rgb{255, 255, 255});
  CHECK(heat_map_colour(1.3, 0.3, 1.0) == Rgb{178, 24, 43});
  CHECK(heat_map_colour(-0.7, 0.3, 1.0) == Rgb{33, 102, 172});
  CHECK(heat_map_colour(-5.0, 0.3, 1.0) == Rgb{33, 102, 172});  // clamped
  const Rgb half = heat_map_colour(0.8, 0.3, 1.0);               // halfway from white to red
  CHECK(half == Rgb{static_cast<unsigned char>(std::lround(255 + (178 - 255) * 0.5)), static_cast<unsigned char>(std::lround(255 + (24 - 255) * 0.5)),
                    static_cast<unsigned char>(std::lround(255 + (43 - 255) * 0.5))});

  HeatMap map;
  map.title = "t";
  map.x_label = "x";
  map.y_label = "y";
  map.x = {0.0, 1.0, 2.0};
  map.y = {10.0, 20.0};
  map.values = {{-2.0, 0.0, 1.0}, {2.0, std::nan(""), -1.0}};  // rows: y = 10 (bottom), y = 20 (top)
  const RgbImage image = draw_heat_map(map);
  // Cells span x from 110 to 780 and y from 50 (top) to 530; sample each a few pixels inside its top-left corner.
  const int left = 110, top = 50, w = 900 - 110 - 120, h = 600 - 50 - 70;
  auto cell = [&](int i, int j) { return pixel(image, left + i * w / 3 + 6, top + h - (j + 1) * h / 2 + 6); };
  CHECK(cell(0, 0) == heat_map_colour(-2.0, 0, 2.0));
  CHECK(cell(1, 0) == Rgb{255, 255, 255});
  CHECK(cell(2, 0) == heat_map_colour(1.0, 0, 2.0));
  CHECK(cell(0, 1) == heat_map_colour(2.0, 0, 2.0));
  CHECK(cell(1, 1) == Rgb{200, 200, 200});  // no value: grey
  CHECK(cell(2, 1) == heat_map_colour(-1.0, 0, 2.0));
  map.values.pop_back();
  CHECK_THROWS_AS(draw_heat_map(map), InputError);
}
