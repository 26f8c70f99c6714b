// Grouped bar charts (plot/bar_chart.h): a bar's area is proportional to its value, and the value
// labels fit their bars however many series share a group.
#include <catch2/catch.hpp>
#include <cmath>
#include <fmt/format.h>

#include "plot/bar_chart.h"

using namespace needle;

namespace {

bool has_colour(const RgbImage& image, int x, int y, const Rgb& c) {
  const size_t p = 3 * (static_cast<size_t>(y) * image.width + x);
  return image.rgb[p] == c[0] && image.rgb[p + 1] == c[1] && image.rgb[p + 2] == c[2];
}

long count_pixels(const RgbImage& image, const Rgb& c) {
  long n = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) n += has_colour(image, x, y, c);
  return n;
}

// The longest run of pixels of colour c in any row (along x) or, with along_y, in any column.
int longest_run(const RgbImage& image, const Rgb& c, bool along_y = false) {
  const int lines = along_y ? image.width : image.height, length = along_y ? image.height : image.width;
  int best = 0;
  for (int line = 0; line < lines; ++line) {
    int run = 0;
    for (int k = 0; k < length; ++k) {
      run = (along_y ? has_colour(image, line, k, c) : has_colour(image, k, line, c)) ? run + 1 : 0;
      best = std::max(best, run);
    }
  }
  return best;
}

}  // namespace

TEST_CASE("A bar's area is proportional to its value, up or down", "[plot]") {
  const Rgb red{200, 10, 10}, green{10, 150, 10};
  BarChart chart;
  chart.title = "t";
  chart.categories = {"legend here", "bars"};  // the first group stays empty under the legend
  const double a = 0.9, b = -0.3;
  chart.series = {{"a", {NAN, a}, red}, {"b", {NAN, b}, green}};
  const RgbImage image = draw_bar_chart(chart);
  // Each colour also fills a legend swatch: measure those on a chart with the same axes whose bars
  // are drawn in a third colour.
  BarChart legend_only = chart;
  legend_only.series[0].values = {NAN, NAN};
  legend_only.series[1].values = {NAN, NAN};
  legend_only.series.push_back({"c", {a, b}, Rgb{0, 0, 200}});
  const RgbImage legend_image = draw_bar_chart(legend_only);
  const long red_bar = count_pixels(image, red) - count_pixels(legend_image, red);
  const long green_bar = count_pixels(image, green) - count_pixels(legend_image, green);
  INFO("bar pixels " << red_bar << " and " << green_bar);
  REQUIRE(green_bar > 100);
  CHECK(static_cast<double>(red_bar) / static_cast<double>(green_bar) == Approx(std::abs(a / b)).epsilon(0.05));
}

TEST_CASE("Value labels fit their bars when many series share a group", "[plot]") {
  BarChart chart;
  chart.title = "six models, four needles";
  chart.categories = {"SB", "LMB", "AMB", "HMB"};
  const Rgb probe{1, 2, 3};
  for (int k = 0; k < 6; ++k)
    chart.series.push_back({fmt::format("model {}", k), {-1.137, 0.56, 1.629, 2.578}, k == 3 ? probe : Rgb{100, 100, static_cast<unsigned char>(40 * k)}});
  const RgbImage image = draw_bar_chart(chart);
  TextWriter small(13);
  const int label = small.width("+2.58");
  INFO("label " << label << " px, image " << image.width << " px wide");
  REQUIRE(label > 0);  // the font is installed (scripts/install-deps.sh)
  CHECK(longest_run(image, probe) >= label);
  CHECK(image.width > chart.width_px);  // 24 bars of a 900 px chart could not hold their labels
}

TEST_CASE("The legend stays off the bars, however long its labels", "[plot]") {
  // One bar filling the axes' full height under a legend label long enough to cross it: the column
  // through the bar's middle is the bar's colour from the top of the axes down to the zero line.
  const Rgb bar{20, 120, 20};
  BarChart chart;
  chart.title = "t";
  chart.categories = {"one"};
  chart.series = {{std::string(60, 'W'), {1.0}, bar}};
  const RgbImage image = draw_bar_chart(chart);
  int run = 0, longest = 0;
  const int middle = image.width / 2 + 35;  // the axes start 90 px from the left, end 20 px from the right
  for (int y = 0; y < image.height; ++y) {
    run = has_colour(image, middle, y, bar) ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  const int axes_height = chart.height_px - 50 - 60;
  INFO("longest run " << longest << " px of an axes " << axes_height << " px high");
  CHECK(longest >= axes_height - 4);
  CHECK(image.height > chart.height_px);  // the legend's rows were added below
}

TEST_CASE("A bar's range is a whisker as long as the range, inside the axes", "[plot]") {
  // A bar at 1.0 whose range, 0.8 to 1.6, reaches past every bar: the axes must grow to hold it,
  // and the whisker's stem is then 0.8 / 1.0 of the bar's height (give or take its 1 px caps).
  const Rgb bar{20, 120, 20}, whisker{200, 0, 200};
  BarChart chart;
  chart.title = "t";
  chart.categories = {"one"};
  chart.range_color = whisker;
  chart.series = {{"a", {1.0}, bar, {{0.8, 1.6}}}};
  const RgbImage image = draw_bar_chart(chart);
  const int stem = longest_run(image, whisker, true), bar_height = longest_run(image, bar, true);
  INFO("stem " << stem << " px, bar " << bar_height << " px");
  REQUIRE(bar_height > 100);
  CHECK(std::abs(stem - 0.8 * bar_height) <= 4);
  int whisker_top = image.height;  // the axes start 50 px from the top, under the title
  for (int y = image.height - 1; y >= 0; --y)
    for (int x = 0; x < image.width; ++x)
      if (has_colour(image, x, y, whisker)) whisker_top = y;
  CHECK(whisker_top >= 50 - 1);
  // No range label: the legend holds the series alone. With one, it gains the whisker's entry.
  BarChart labelled = chart;
  labelled.range_label = "spread";
  CHECK(count_pixels(draw_bar_chart(labelled), whisker) > count_pixels(image, whisker));
  // A NaN end draws no whisker, and the axes are the bar's own.
  BarChart none = labelled;
  none.series[0].ranges = {{NAN, 1.6}};
  CHECK(count_pixels(draw_bar_chart(none), whisker) == 0);
}
