// The groove-fill measure against closed forms: an empty groove, a groove filled to its floor, tissue
// hanging at a known height, a groove half inside the block, and the floor-contact share.
#include <catch2/catch.hpp>
#include <cmath>

#include "solver/insertion/groove_fill.h"

using namespace needle;

namespace {

// A half-model lattice of particles (spacing h) over x in [x0, x1], y in [y0, y1], z in [0, 1].
GrooveFillInput lattice(double h, double x0, double x1, double y0, double y1) {
  GrooveFillInput in;
  in.groove = GrooveBox{-0.07, -3.0, -25.0};
  in.radius_mm = 0.5;
  in.tissue_min_x_mm = -100, in.tissue_max_x_mm = 100;
  for (double x = x0; x <= x1 + 1e-9; x += h)
    for (double y = y0; y <= y1 + 1e-9; y += h)
      for (double z = 0; z <= 1 + 1e-9; z += h) {
        in.reference_points.emplace_back(x, y, z);
        in.spacing_mm.push_back(h);
        in.touches_floor.push_back(0);
      }
  return in;
}

}  // namespace

TEST_CASE("Groove fill: empty, full and hanging tissue give the closed-form fill", "[solver][groove]") {
  const double h = 0.2, floor = -0.07, R = 0.5;
  SECTION("no particle in the groove: fill 0, gap the full depth") {
    GrooveFillInput in = lattice(h, -30, 5, 0.7, 2.0);  // all above the rod
    const GrooveFill f = measure_groove_fill(in);
    CHECK(f.length_in_tissue_mm == Approx(22.0));
    CHECK(f.groove_fill == 0);
    CHECK(f.mean_gap_mm == Approx(R - floor));
    CHECK(f.particles_in_groove == 0);
  }
  SECTION("tissue down to the floor: fill 1, no gap") {
    GrooveFillInput in = lattice(h, -30, 5, floor + 0.5 * h, 2.0);
    const GrooveFill f = measure_groove_fill(in);
    CHECK(f.groove_fill == Approx(1.0));
    CHECK(f.mean_gap_mm == Approx(0.0).margin(1e-12));
  }
  SECTION("tissue hanging 0.25 mm above the floor: fill (R - b) / depth") {
    const double lowest = floor + 0.25 + 0.5 * h;  // lower edge 0.25 above the floor
    GrooveFillInput in = lattice(h, -30, 5, lowest, 2.0);
    const GrooveFill f = measure_groove_fill(in);
    CHECK(f.groove_fill == Approx((R - (floor + 0.25)) / (R - floor)).epsilon(1e-9));
    CHECK(f.mean_gap_mm == Approx(0.25).epsilon(1e-9));
  }
  SECTION("tissue only over the front half of the groove, touching the floor there") {
    GrooveFillInput in = lattice(h, -14 + 0.5 * h, 5, floor + 0.5 * h, 2.0);
    for (size_t i = 0; i < in.reference_points.size(); ++i)
      in.touches_floor[i] = std::abs(in.reference_points[i].y() - (floor + 0.5 * h)) < 1e-9 ? 1 : 0;
    const GrooveFill f = measure_groove_fill(in);
    CHECK(f.groove_fill == Approx(11.0 / 22.0).epsilon(0.01));
    CHECK(f.floor_contact_fraction == Approx(11.0 / 22.0).epsilon(0.01));
  }
  SECTION("only the groove inside the block counts") {
    GrooveFillInput in = lattice(h, -30, 5, floor + 0.5 * h, 2.0);
    in.tissue_min_x_mm = -10;  // the block's entry face pulled back to the needle's frame
    const GrooveFill f = measure_groove_fill(in);
    CHECK(f.length_in_tissue_mm == Approx(7.0));
    CHECK(f.groove_fill == Approx(1.0));
  }
  SECTION("particles outside the section's width do not fill it") {
    GrooveFillInput in = lattice(h, -30, 5, floor + 0.5 * h, 2.0);
    for (auto& X : in.reference_points) X.z() += 0.6;  // all beyond the rod's radius
    CHECK(measure_groove_fill(in).groove_fill == 0);
  }
}
