// Speed against error of the grinding CAD: for each preset and tessellation level (chord
// tolerance, fewest segments per facet arc; the middle row is the default), the median build
// time, the triangle count, and the worst facet-area and volume error against the smooth solid.
//   build/bench/bench_tip [repeats]
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fmt/format.h>
#include <vector>

#include "geometry/cad_solid.h"
#include "geometry/exact_measures.h"
#include "geometry/surface_measures.h"

using namespace needle;

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  fmt::print("{:<5} {:<5} {:>10} {:>8} {:>10} {:>10} {:>14} {:>12}\n", "tip", "model", "chord_mm", "min_arc", "triangles",
             "build_s", "max_area_err%", "volume_err%");
  for (const std::string& name : preset_names())
    for (bool half : {false, true})
      for (const auto& [chord, min_segments] : {std::pair{4e-3, 4}, std::pair{1e-3, 24}, std::pair{2.5e-4, 48}}) {
        GrindingRecipe recipe = preset_recipe(name);
        recipe.tessellation.chord_tolerance_mm = chord;
        recipe.tessellation.min_segments_per_arc = min_segments;
        std::vector<double> seconds;
        CadSolid solid;
        for (int r = 0; r < repeats; ++r) {
          solid = build_cad_solid(recipe, half);
          seconds.push_back(solid.build_seconds);
        }
        std::sort(seconds.begin(), seconds.end());
        ExactOptions exact;
        exact.half_model = half;
        const std::vector<double> areas = area_by_tag_mm2(solid.surface);
        double worst = 0;
        for (size_t i = 0; i < solid.tip.facets.size(); ++i) {
          const double e = exact_facet_area_mm2(solid.tip, static_cast<int>(i), exact);
          const int tag = solid.surface.tag_index(solid.tip.facets[i].name);
          if (e > 1e-4 && tag >= 0) worst = std::max(worst, std::abs(areas[tag] / e - 1));
        }
        const double volume_error = enclosed_volume_mm3(solid.surface) / exact_volume_mm3(solid.tip, exact) - 1;
        fmt::print("{:<5} {:<5} {:>10.2e} {:>8} {:>10} {:>10.3f} {:>14.4f} {:>12.4f}\n", name, half ? "half" : "full", chord, min_segments,
                   solid.surface.num_faces(), seconds[seconds.size() / 2], 100 * worst, 100 * volume_error);
      }
  return 0;
}
