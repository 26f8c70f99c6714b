// The particles a scene describes (runs/scene_particles.h): tissue.offset_y_mm moves the whole set across the path,
// the fine band with it, so that it is a phase of the lattice against the needle's path (a closed form: the same
// particles translated); the effective scene writes the key only when it is set, and a shift that brings the block's
// side faces near the path is refused.
#include <catch2/catch.hpp>
#include <string>

#include "core/input_error.h"
#include "runs/scene.h"
#include "runs/scene_particles.h"

TEST_CASE("tissue.offset_y_mm translates every particle across the path, the fine band with them", "[runs][scene]") {
  for (const char* grading : {"tensor", "nested"}) {
    INFO(grading);
    const std::string block = std::string(R"({"tissue": {"enabled": true, "size_mm": [3, 5, 2], "spacing_mm": 0.4, "path_refinement": 2,)") +
                              R"("path_half_width_mm": 1.0, "path_grading": ")" + grading + R"("}})";
    needle::Scene scene = needle::parse_scene(block, "(test)");
    const needle::ParticleSet centred = needle::scene_particles(scene);
    scene.tissue.offset_y_mm = 0.13;
    const needle::ParticleSet shifted = needle::scene_particles(scene);
    REQUIRE(shifted.num_particles() == centred.num_particles());
    REQUIRE(centred.num_particles() > 100);
    double worst = 0;
    for (int i = 0; i < centred.num_particles(); ++i) {
      worst = std::max(worst, (shifted.x_mm.row(i) - centred.x_mm.row(i) - Eigen::RowVector3d(0, 0.13, 0)).norm());
      CHECK(shifted.spacing_mm[i] == Approx(centred.spacing_mm[i]).epsilon(1e-12));
    }
    CHECK(worst < 1e-12);
    // The band is the fine one still: the smallest spacing is half the coarse one, as without the shift.
    CHECK(shifted.spacing_mm.minCoeff() == Approx(centred.spacing_mm.minCoeff()));
  }
}

TEST_CASE("tissue.offset_y_mm reads back, is written only when set, and may not bring a side face near the path", "[runs][scene]") {
  const needle::Scene plain = needle::parse_scene(R"({"tissue": {"enabled": true}})", "(test)");
  CHECK_FALSE(needle::scene_to_json(plain)["tissue"].contains("offset_y_mm"));
  const needle::Scene shifted = needle::parse_scene(R"({"tissue": {"enabled": true, "offset_y": "50 um"}})", "(test)");
  CHECK(shifted.tissue.offset_y_mm == Approx(0.05));
  CHECK(needle::scene_to_json(shifted)["tissue"]["offset_y_mm"].get<double>() == Approx(0.05));
  try {
    needle::parse_scene(R"({"tissue": {"enabled": true, "size_mm": [40, 2, 2], "offset_y_mm": 0.6}})", "bad.json");
    FAIL("accepted");
  } catch (const needle::InputError& e) {
    CHECK(std::string(e.what()).find("tissue.offset_y_mm: 0.6 mm moves the block's side faces within a rod's radius of the path") !=
          std::string::npos);
  }
}
