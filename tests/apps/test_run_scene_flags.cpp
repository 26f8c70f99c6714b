// `needle run`'s scene flags on the small block, each as a user gives it: the effective scene says so, the solver
// feels it (against the same run without it, or a closed form), and a bad value is refused with one line and no
// run folder. The runs are those of run_fixtures.h.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <nlohmann/json.hpp>

#include "runs/csv_table.h"
#include "runs/scene.h"
#include "runs/scene_needle.h"
#include "cli_run.h"
#include "run_fixtures.h"

namespace fs = std::filesystem;
using namespace needle_test;

TEST_CASE("needle run --no-needle-cut: the tissue separates by bond failure alone", "[apps][lspg][gmsh][slow]") {
  // The same short insertion with and without the needle's cut: the flag turns the cut off and says
  // so in the effective scene; with the cut on, the rod's passage cuts bonds.
  auto run_variant = [](const std::string& name, const std::string& flags) {
    const RunFiles run = run_rod_into_small_block(name, flags);
    return std::pair{run.summary, run.scene};
  };
  const auto [cut_summary, cut_scene] = run_variant("insertion_cut", "");
  const auto [plain_summary, plain_scene] = run_variant("insertion_no_cut", "--no-needle-cut");
  CHECK(cut_scene["tissue"]["separation"]["needle_cut"] == true);
  CHECK(plain_scene["tissue"]["separation"]["needle_cut"] == false);
  CHECK(cut_summary["bonds_cut_by_needle"].get<long>() > 0);
  CHECK_FALSE(plain_summary.contains("bonds_cut_by_needle"));  // the needle's cut is off: no model, no entry
  CHECK(plain_summary["status"] == "finished");
}

TEST_CASE("needle run --tissue-law stiffening_elastic: the scene says so and the stiffened tissue resists harder", "[apps][lspg][gmsh][slow]") {
  // The same short insertion at the same E under both laws: the stiffening law adds k eps^n to the same
  // small-strain modulus, so the tissue's reaction on the rod must be larger. The default law is not
  // written into the effective scene (stored scenes and runs stay as they were).
  auto run_variant = [](const std::string& name, const std::string& flags) {
    const RunFiles run = run_rod_into_small_block(name, "--tissue-E-MPa 0.03 " + flags);
    return std::pair{run.scene, std::abs(run.history.column("contact_force_x_N").back())};
  };
  const auto [card_scene, card_drag_N] = run_variant("law_card", "");
  const auto [stiff_scene, stiff_drag_N] = run_variant("law_stiffening", "--tissue-law stiffening_elastic");
  CHECK_FALSE(card_scene["tissue"]["material"].contains("law"));
  CHECK(stiff_scene["tissue"]["material"]["law"] == "stiffening_elastic");
  INFO("drag: card " << card_drag_N << " N, stiffening " << stiff_drag_N << " N");
  CHECK(card_drag_N > 0);
  CHECK(stiff_drag_N > 1.2 * card_drag_N);
}

TEST_CASE("needle run --speed-m-per-s: the scene says so and the drive ends when the closed-form profile does", "[apps][lspg][gmsh][slow]") {
  // The rod's scene ramps 0 -> v in 0.02 ms, then runs at v to 0.8 mm: it ends at
  // t = 0.02 + (0.8 - v 0.02 / 2) / v ms. Halving the speed must nearly double the run's simulated time.
  auto end_of_run = [](const std::string& name, double speed_m_per_s) {
    const RunFiles run = run_rod_into_small_block(name, fmt::format("--speed-m-per-s {}", speed_m_per_s));
    CHECK(run.scene["motion"]["speed_m_per_s"].get<double>() == speed_m_per_s);
    CHECK(run.summary["status"] == "finished");
    CHECK(run.summary["insertion_mm"].get<double>() == Approx(0.8).epsilon(1e-6));
    return run.history.column("time_ms").back();
  };
  for (const double v : {8.0, 4.0}) {
    const double expected_ms = 0.02 + (0.8 - 0.5 * v * 0.02) / v;
    const double end_ms = end_of_run(fmt::format("speed_{}", v), v);
    INFO("v " << v << " m/s: history ends at " << end_ms << " ms, profile " << expected_ms << " ms");
    CHECK(end_ms == Approx(expected_ms).epsilon(1e-6));
  }
}

TEST_CASE("needle run --hold-ms: the base stops at the travel's end, the drive does no more work, the run ends after the hold",
          "[apps][lspg][gmsh][slow]") {
  // The rod's scene at 8 m/s reaches 0.8 mm at t = 0.02 + (0.8 - 0.08) / 8 = 0.11 ms; a 0.06 ms hold follows. While the base is
  // still its reaction does no work, so the drive's work must not change over the hold, while the tissue still moves.
  const RunFiles run = run_rod_into_small_block("hold", "--hold-ms 0.06");
  const nlohmann::json& summary = run.summary;
  const needle::CsvTable& history = run.history;
  CHECK(run.scene["motion"]["hold_ms"].get<double>() == 0.06);
  CHECK(summary["status"] == "finished");
  const auto& time = history.column("time_ms");
  const auto& insertion = history.column("insertion_mm");
  const auto& drive_work = history.column("drive_work_mJ");
  const double travel_end_ms = 0.11;
  CHECK(time.back() == Approx(travel_end_ms + 0.06).epsilon(1e-6));
  std::size_t at_stop = 0;
  while (at_stop < time.size() && time[at_stop] < travel_end_ms) ++at_stop;
  REQUIRE(at_stop + 2 < time.size());  // rows within the hold
  CHECK(time[at_stop] < travel_end_ms + 0.02 + 1e-9);  // the first row after the stop (rows every 0.02 ms)
  CHECK(drive_work[at_stop] > 0);
  for (std::size_t i = at_stop; i < time.size(); ++i) {
    CHECK(insertion[i] == Approx(0.8).epsilon(1e-9));
    CHECK(drive_work[i] == Approx(drive_work[at_stop]).epsilon(1e-9));
  }
  CHECK(summary["energy_balance_error"].get<double>() < 0.02);
}

TEST_CASE("needle run --tissue-size-mm: the lattice fills the given block, and fixed faces further out hold the tissue less stiffly",
          "[apps][lspg][gmsh][slow]") {
  // The lattice has round(size / 0.4) + 1 nodes per axis. The same rod pushed into a block whose fixed faces (y = +-Y/2, z = Z)
  // stand further from it meets tissue that is less confined: it stores less strain energy at every sample of the run.
  // (The rod's drag is not compared: on a lattice six particles long, the contact force of one sample swings by a
  // factor of 40 between samples as single particles enter and leave the skin.)
  struct Block {
    long particles;
    std::vector<double> internal_mJ;
  };
  auto push_into = [](const std::string& name, const std::string& size_flag) {
    const RunFiles run = run_rod_into_small_block(name, size_flag);
    CHECK(run.summary["status"] == "finished");
    return std::pair{run.scene["tissue"]["size_mm"], Block{run.summary["particles"].get<long>(), run.history.column("tissue_internal_mJ")}};
  };
  const auto [narrow_size, narrow] = push_into("size_narrow", "");
  const auto [wide_size, wide] = push_into("size_wide", "--tissue-size-mm 2,4,2.4");
  CHECK(narrow_size == nlohmann::json::array({2.0, 2.4, 1.2}));
  CHECK(wide_size == nlohmann::json::array({2.0, 4.0, 2.4}));
  CHECK(narrow.particles == 6 * 7 * 4);
  CHECK(wide.particles == 6 * 11 * 7);
  REQUIRE(narrow.internal_mJ.size() == wide.internal_mJ.size());
  REQUIRE(narrow.internal_mJ.size() >= 5);
  for (size_t i = 1; i < narrow.internal_mJ.size(); ++i) {  // row 0 is the start, before the rod touches the block
    INFO("sample " << i << ": strain energy narrow " << narrow.internal_mJ[i] << " mJ, wide " << wide.internal_mJ[i] << " mJ");
    CHECK(wide.internal_mJ[i] > 0);
    CHECK(wide.internal_mJ[i] < narrow.internal_mJ[i]);
  }

  refused_on_small_block("size_bad", "--tissue-size-mm 2,0,1.2", "--tissue-size-mm 2,0,1.2: tissue.size_mm must be three positive lengths");
}

TEST_CASE("needle run --slit-half-height-mm: the symmetry plane opens behind the tip, and its particles leave the plane",
          "[apps][lspg][gmsh][slit][slow]") {
  // The same rod pushed 0.8 mm in, with and without a slit 0.9 mm either side of the rod's axis. The blunt rod pushes the
  // plane's particles within its radius (0.5 mm) ahead of it, so behind its end (x < 0.8) lie those at y = +-0.8, x = 0 and
  // 0.4: four. Once open they may leave the plane, pulled by the tissue beside them.
  const RunFiles closed = run_rod_into_small_block("slit_closed", "");
  const RunFiles open = run_rod_into_small_block("slit_open", "--slit-half-height-mm 0.9");
  CHECK_FALSE(closed.scene["tissue"]["separation"].contains("slit"));  // written only when on
  CHECK(open.scene["tissue"]["separation"]["slit"]["half_height_mm"].get<double>() == 0.9);
  CHECK_FALSE(closed.summary.contains("slit"));  // a separation model that is off reports nothing
  CHECK(open.summary["slit"]["particles_opened"].get<long>() == 4);
  CHECK(open.summary["slit"]["max_opening_mm"].get<double>() > 0);
  CHECK(open.summary["slit"]["mean_opening_mm"].get<double>() > 0);
  CHECK(open.summary["slit"]["mean_opening_mm"].get<double>() <= open.summary["slit"]["max_opening_mm"].get<double>());
  CHECK(open.summary["status"] == "finished");
  CHECK(open.summary["max_energy_balance_error"].get<double>() < 0.05);

  refused_in_one_line("slit_bad", "--slit-half-height-mm -1", "--slit-half-height-mm -1: tissue.separation.slit.half_height_mm must not be negative (got -1)");
}

TEST_CASE("needle run --decel-time-ms: a ramped stop leaves the needle far less ringing than an instantaneous one", "[apps][lspg][gmsh][slow]") {
  // The steel rod, stopped at once from 8 m/s, keeps its kinetic energy (0.6 mJ for this 6 mm half rod) ringing axially
  // with no damping. Ramped to rest over 0.02 ms, four axial periods (4 L / c = 4.9 us), it keeps a small fraction.
  auto needle_kinetic_in_hold = [](const std::string& name, const std::string& flags, double stop_ms) {
    const needle::CsvTable history = run_rod_into_small_block(name, flags).history;
    const auto time = history.column("time_ms"), kinetic = history.column("needle_kinetic_mJ"), insertion = history.column("insertion_mm");
    CHECK(time.back() == Approx(stop_ms + 0.06).epsilon(1e-6));
    CHECK(insertion.back() == Approx(0.8).epsilon(1e-9));
    double peak_mJ = 0;
    for (std::size_t i = 0; i < time.size(); ++i)
      if (time[i] > stop_ms + 0.005) peak_mJ = std::max(peak_mJ, kinetic[i]);
    return peak_mJ;
  };
  // Travel ends at 0.02 + (0.8 - 0.08) / 8 = 0.11 ms at once; with the ramp at 0.02 + (0.8 - 0.16) / 8 + 0.02 = 0.12 ms.
  const double instant_mJ = needle_kinetic_in_hold("stop_instant", "--hold-ms 0.06", 0.11);
  const double ramped_mJ = needle_kinetic_in_hold("stop_ramped", "--decel-time-ms 0.02 --hold-ms 0.06", 0.12);
  INFO("needle kinetic energy in the hold: instantaneous stop " << instant_mJ << " mJ, ramped " << ramped_mJ << " mJ");
  CHECK(instant_mJ > 0.1);
  CHECK(ramped_mJ < 0.2 * instant_mJ);
}

TEST_CASE("needle run --relaxing-shear-fraction: the scene says so, the relaxed gel drags the rod less, and the balance books the loss",
          "[apps][lspg][gmsh][viscoelastic][slow]") {
  // The rod's 0.11 ms push with 90 % of the shear stress relaxing at tau 0.01 ms: the tissue the rod has passed keeps a tenth
  // of its shear stress, so the rod's drag must fall well below the elastic card's, while the energy balance (the stress
  // power is internal work) still closes. Without the flag the keys are not written (stored scenes and runs stay as they were).
  const RunFiles card = run_rod_into_small_block("relax_card", "");
  const RunFiles gel = run_rod_into_small_block("relax_gel", "--relaxing-shear-fraction 0.9 --relaxation-time-ms 0.01");
  CHECK_FALSE(card.scene["tissue"]["material"].contains("relaxing_shear_fraction"));
  CHECK(gel.scene["tissue"]["material"]["relaxing_shear_fraction"].get<double>() == 0.9);
  CHECK(gel.scene["tissue"]["material"]["relaxation_time_ms"].get<double>() == 0.01);
  CHECK(gel.summary["status"] == "finished");
  const double card_drag_N = std::abs(card.history.column("contact_force_x_N").back());
  const double gel_drag_N = std::abs(gel.history.column("contact_force_x_N").back());
  INFO("drag: card " << card_drag_N << " N, relaxing gel " << gel_drag_N << " N; balance " << gel.summary["energy_balance_error"]);
  CHECK(card_drag_N > 0);
  CHECK(gel_drag_N < 0.8 * card_drag_N);
  CHECK(gel.summary["energy_balance_error"].get<double>() < 0.02);

  for (const auto& [flags, message] : {std::pair<std::string, std::string>{"--relaxing-shear-fraction 1", "--relaxing-shear-fraction 1: tissue relaxing_shear_fraction must lie in [0, 1)"},
                                       {"--relaxation-time-ms 0.5", "--relaxation-time-ms 0.5: tissue.material.relaxation_time_ms needs a relaxing_shear_fraction above 0"},
                                       {"--relaxing-shear-fraction 0.5 --relaxation-time-ms -1", "--relaxation-time-ms -1: tissue relaxation_time_ms must be positive"}}) {
    refused_on_small_block("relax_bad", flags, message);
  }
}

TEST_CASE("needle run --cutting-pressure-mpa: the scene says so, the tip pays the cutting work, bad input is refused",
          "[apps][lspg][gmsh][cutting][slow]") {
  // The SB pushed 0.8 mm into the small block with and without a cutting pressure of 0.2 MPa: the key is written only
  // when on; the work goes into the summary and into the balance (which must still close); the needle is held back harder.
  const RunFiles free_cut = run_sb_into_small_block("cutting_free", "");
  const RunFiles paid_cut = run_sb_into_small_block("cutting_paid", "--cutting-pressure-mpa 0.2");
  CHECK_FALSE(free_cut.scene["tissue"].contains("cutting"));
  CHECK(paid_cut.scene["tissue"]["cutting"]["pressure_MPa"].get<double>() == 0.2);
  CHECK_FALSE(free_cut.summary.contains("cutting"));  // no cutting resistance, no entry
  const double work_mJ = paid_cut.summary["cutting"]["work_mJ"].get<double>();
  const double free_drag_N = std::abs(free_cut.history.column("contact_force_x_N").back());
  const double paid_drag_N = std::abs(paid_cut.history.column("contact_force_x_N").back());
  INFO("cutting work " << work_mJ << " mJ; drag " << free_drag_N << " N free, " << paid_drag_N << " N paid; balance "
                       << paid_cut.summary["energy_balance_error"]);
  CHECK(work_mJ > 0);
  CHECK(paid_drag_N > free_drag_N);
  CHECK(paid_cut.summary["energy_mJ"]["friction_dissipation"].get<double>() > work_mJ);
  CHECK(paid_cut.summary["energy_balance_error"].get<double>() < 0.02);
  // The loaded facets are the tip's own, whatever a recipe names them.
  {
    const fs::path recipe = fresh_folder("cutting_recipe") / "bevel.json";
    write(recipe, R"({"name": "one bevel", "groove": {"length_mm": 22.0, "remaining_thickness_mm": 0.43, "start_behind_tip_mm": 3.0},)"
                  R"("grinds": [{"name": "bevel", "tilt_deg": 23.5, "rotation_deg": 0, "depth_mm": 1.0}]})");
    const RunFiles named = run_sb_into_small_block("cutting_named", "--cutting-pressure-mpa 0.2", R"("recipe": ")" + recipe.string() + R"(")");
    CHECK(named.summary["cutting"]["work_mJ"].get<double>() > 0.5 * work_mJ);
  }

  // A negative pressure, and a needle without tip facets to load (the plain rod): one line, exit 2, no run folder.
  for (const auto& [flags, message] : {std::pair<std::string, std::string>{"--cutting-pressure-mpa -1", "--cutting-pressure-mpa -1: tissue.cutting.pressure_MPa must not be negative"},
                                       {"--cutting-pressure-mpa 0.2", "a cutting pressure needs a needle with tip facets"}}) {
    refused_on_small_block("cutting_bad", flags, message);
  }
}

TEST_CASE("needle run --crack-reach-mm: the scene says so, the tip's crack cuts bonds past the rod, bad input is refused",
          "[apps][lspg][gmsh][crack][slow]") {
  // The SB pushed 0.8 mm in, with and without a horizontal crack 1 mm long from tip point A (at the rod's bottom, y = -0.5):
  // the lattice's bonds from y = -0.8 to -0.4 cross its plane beside the rod, where the needle's body never is, so the
  // needle alone cuts none of them. The key is written only when on, and the balance still closes.
  const RunFiles uncracked = run_sb_into_small_block("crack_off", "");
  const RunFiles cracked = run_sb_into_small_block("crack_on", "--crack-reach-mm 1.0 --crack-angles-deg 0");
  CHECK_FALSE(uncracked.scene["tissue"]["separation"].contains("crack"));
  CHECK(cracked.scene["tissue"]["separation"]["crack"]["reach_mm"].get<double>() == 1.0);
  CHECK(cracked.scene["tissue"]["separation"]["crack"]["angles_deg"] == nlohmann::json::array({0.0}));
  CHECK_FALSE(uncracked.summary.contains("crack"));  // a separation model that is off reports nothing
  const long crack_cuts = cracked.summary["crack"]["bonds_cut"].get<long>();
  INFO("bonds cut by the crack " << crack_cuts << ", by the needle " << cracked.summary["bonds_cut_by_needle"] << " (without the crack "
                                 << uncracked.summary["bonds_cut_by_needle"] << "); balance " << cracked.summary["energy_balance_error"]);
  CHECK(crack_cuts > 0);
  CHECK(cracked.summary["crack"]["crack_s"].get<double>() > 0);
  CHECK(cracked.summary["bonds_broken"].get<long>() >= crack_cuts + cracked.summary["bonds_cut_by_needle"].get<long>());
  CHECK(cracked.summary["status"] == "finished");
  CHECK(cracked.summary["energy_balance_error"].get<double>() < 0.02);

  // A front 0.4 mm ahead of A splits the gel the tip has not reached yet: the same crack plus the slab ahead of the tip.
  const RunFiles leading = run_sb_into_small_block("crack_lead", "--crack-reach-mm 1.0 --crack-lead-mm 0.4");
  CHECK(leading.scene["tissue"]["separation"]["crack"]["lead_mm"].get<double>() == 0.4);
  CHECK(cracked.scene["tissue"]["separation"]["crack"]["lead_mm"].get<double>() == 0.0);
  INFO("bonds cut by the crack with its front 0.4 mm ahead " << leading.summary["crack"]["bonds_cut"]);
  CHECK(leading.summary["crack"]["bonds_cut"].get<long>() > crack_cuts);
  CHECK(leading.summary["status"] == "finished");

  // A negative reach or lead, an angle out of range, a crack's shape without a crack, and a needle without a tip point (the
  // plain rod): one line, exit 2, no run folder.
  for (const auto& [flags, message] : {std::pair<std::string, std::string>{"--crack-reach-mm -1", "--crack-reach-mm -1: tissue.separation.crack.reach_mm must not be negative"},
                                       {"--crack-reach-mm 1 --crack-lead-mm -0.5", "--crack-lead-mm -0.5: tissue.separation.crack.lead_mm must not be negative"},
                                       {"--crack-lead-mm 0.5", "--crack-lead-mm 0.5: tissue.separation.crack.lead_mm: the crack's shape (its angles and lead) needs a crack: tissue.separation.crack.reach_mm above 0"},
                                       {"--crack-reach-mm 1 --crack-angles-deg 0,200", "--crack-angles-deg 0,200: tissue.separation.crack.angles_deg must lie in [-180, 180] (got 200)"},
                                       {"--crack-reach-mm 1", "a crack from the tip point needs a needle with a ground tip point"}}) {
    refused_in_one_line("crack_bad", flags, message);
  }
}

TEST_CASE("needle run --groove-start-mm: the scene says so, the built needle's groove floor starts there, bad input is refused",
          "[apps][gmsh][scene][slow]") {
  // The paper does not say where the groove starts. The scene key moves the groove's front wall of any ground tip: the
  // groove box and the mesh's groove_floor nodes must start that far behind A, and the default stays the presets' 3 mm.
  auto groove_front_x = [](const std::string& needle_keys) {
    const needle::Scene scene =
        needle::parse_scene(R"({"needle": {)" + needle_keys + R"(, "length_mm": 30, "mesh": {"order": 1, "size_mm": 0.5}}})", "scene.json");
    const needle::SceneNeedle built = needle::build_scene_needle(scene.needle);
    REQUIRE(built.groove.has_value());
    double floor_front_x = -1e9;  // the groove floor's most distal node
    for (int node : needle::nodes_with_tag(built.mesh, "groove_floor")) floor_front_x = std::max(floor_front_x, built.mesh.X(node, 0));
    return std::pair<double, double>{built.groove->front_x_mm - built.tip_point.x(), floor_front_x - built.tip_point.x()};
  };
  const auto [preset_box, preset_floor] = groove_front_x(R"("preset": "AMB")");
  const auto [moved_box, moved_floor] = groove_front_x(R"("preset": "AMB", "groove_start_mm": 5.5)");
  const auto [d_a_box, d_a_floor] = groove_front_x(R"("d_a_mm": -0.1, "groove_start": "7 mm")");
  INFO("groove front behind A: preset " << preset_box << " / " << preset_floor << ", moved " << moved_box << " / " << moved_floor
                                        << ", d_a " << d_a_box << " / " << d_a_floor);
  CHECK(preset_box == Approx(-3.0).margin(1e-9));
  CHECK(preset_floor == Approx(-3.0).margin(1e-6));
  CHECK(moved_box == Approx(-5.5).margin(1e-9));
  CHECK(moved_floor == Approx(-5.5).margin(1e-6));
  CHECK(d_a_box == Approx(-7.0).margin(1e-9));
  CHECK(d_a_floor == Approx(-7.0).margin(1e-6));

  // On the command line: the key is written only when given, and the run goes through.
  const RunFiles presets = run_sb_into_small_block("groove_default", "");
  const RunFiles moved = run_sb_into_small_block("groove_moved", "--groove-start-mm 3.5");  // its 22 mm groove still ends inside the 26 mm rod
  CHECK_FALSE(presets.scene["needle"].contains("groove_start_mm"));
  CHECK(moved.scene["needle"]["groove_start_mm"].get<double>() == 3.5);
  CHECK(moved.summary["status"] == "finished");

  // A start that is not positive, a plain rod (no groove to move), and the scene key on a mesh file: one line, exit 2.
  for (const auto& [flags, message] : {std::pair<std::string, std::string>{"--groove-start-mm 0", "--groove-start-mm 0: needle.groove_start_mm must be positive"},
                                       {"--groove-start-mm 4", "--groove-start-mm 4: needle.groove_start_mm: a groove start moves the groove of a ground tip"}}) {
    refused_in_one_line("groove_bad", flags, message);
  }
  CHECK(message_of(R"({"needle": {"plain_rod": true, "groove_start_mm": 4}})").find("a groove start moves the groove of a ground tip") !=
        std::string::npos);
}

TEST_CASE("needle run --contact-skin-mm, --contact-stiffness-factor: the scene says so, the solver feels both, bad input is refused",
          "[apps][lspg][gmsh][contact][slow]") {
  // The penalty contact's two numerical parameters (solver/contact/needle_tissue_contact.h). The skin holds the particles off the
  // needle's true surface: at stiffness factor 10, without it they sink into the rod until the penalty holds them, with a
  // thin one less, with a thick one (0.04 mm, the default before the skin study) hardly at all (the rod pushed 0.8 mm in).
  // The tissue's step is capped by the contact's own stable step, which goes as 1 / sqrt(k): the default's three times
  // the stiffness of factor 10 takes about sqrt(3) times the steps.
  const RunFiles defaults = run_rod_into_small_block("contact_default", "");
  const RunFiles exact = run_rod_into_small_block("contact_skin0", "--contact-skin-mm 0 --contact-stiffness-factor 10");
  const RunFiles thin = run_rod_into_small_block("contact_skin0.02", "--contact-skin-mm 0.02 --contact-stiffness-factor 10");
  const RunFiles thick = run_rod_into_small_block("contact_skin0.04", "--contact-skin-mm 0.04 --contact-stiffness-factor 10");
  CHECK(defaults.scene["tissue"]["contact"]["skin_mm"].get<double>() == 0.02);
  CHECK(defaults.scene["tissue"]["contact"]["stiffness_factor"].get<double>() == 30.0);
  CHECK(exact.scene["tissue"]["contact"]["skin_mm"].get<double>() == 0.0);
  CHECK(thick.scene["tissue"]["contact"]["skin_mm"].get<double>() == 0.04);
  CHECK(thin.scene["tissue"]["contact"]["stiffness_factor"].get<double>() == 10.0);
  const double depth_exact = exact.summary["max_penetration_mm"].get<double>();
  const double depth_thin = thin.summary["max_penetration_mm"].get<double>();
  const double depth_thick = thick.summary["max_penetration_mm"].get<double>();
  const double steps_ratio = defaults.summary["steps"].get<double>() / thin.summary["steps"].get<double>();
  INFO("deepest particle below the rod's surface at skin 0 / 0.02 / 0.04 mm: " << depth_exact << " / " << depth_thin << " / " << depth_thick
                                                                               << " mm; steps at stiffness 30 over 10: " << steps_ratio);
  CHECK(depth_exact > depth_thin);
  CHECK(depth_thin > depth_thick);
  CHECK(depth_exact > 0.01);
  CHECK(steps_ratio == Approx(std::sqrt(3.0)).epsilon(0.15));
  for (const RunFiles* r : {&defaults, &exact, &thin, &thick}) {
    CHECK(r->summary["status"] == "finished");
    CHECK(r->summary["energy_balance_error"].get<double>() < 0.02);
  }

  // A negative skin, a stiffness factor that is not positive or beyond 1e4: one line, exit 2, no run folder.
  for (const auto& [flags, message] : {std::pair<std::string, std::string>{"--contact-skin-mm -0.01", "--contact-skin-mm -0.01: tissue.contact.skin_mm must not be negative"},
                                       {"--contact-stiffness-factor 0", "--contact-stiffness-factor 0: tissue.contact.stiffness_factor must lie in [0.001, 10000]"},
                                       {"--contact-stiffness-factor 2e4", "--contact-stiffness-factor 2e4: tissue.contact.stiffness_factor must lie in [0.001, 10000] (got 20000)"}}) {
    refused_in_one_line("contact_bad", flags, message);
  }
}

TEST_CASE("needle run --tissue-entry-x-mm: the block starts there, the rod meets no tissue before it, bad input is refused",
          "[apps][lspg][gmsh][contact][slow]") {
  // The flag that shifts the particle lattice against the needle's path (the lattice starts at the entry face), so that a
  // result's run-to-run scatter can be measured. The same block, moved 0.2 mm ahead of the rod's start: the same particles,
  // no contact and no broken bond while the rod's end is short of the face by more than the contact's skin, and the rod's
  // 0.6 mm in the tissue instead of 0.8 cut fewer bonds and strain the block less.
  const RunFiles at_face = run_rod_into_small_block("entry_0", "");
  const RunFiles ahead = run_rod_into_small_block("entry_0.2", "--tissue-entry-x-mm 0.2");
  CHECK(at_face.scene["tissue"]["entry_x_mm"].get<double>() == 0.0);
  CHECK(ahead.scene["tissue"]["entry_x_mm"].get<double>() == 0.2);
  CHECK(ahead.summary["particles"] == at_face.summary["particles"]);
  const double skin_mm = ahead.scene["tissue"]["contact"]["skin_mm"].get<double>();
  const auto insertion = ahead.history.column("insertion_mm"), contacts = ahead.history.column("particles_in_contact"),
             broken = ahead.history.column("bonds_broken");
  int rows_short_of_face = 0;
  for (size_t i = 0; i < insertion.size(); ++i)
    if (insertion[i] < 0.2 - skin_mm) {
      ++rows_short_of_face;
      CHECK(contacts[i] == 0);
      CHECK(broken[i] == 0);
    }
  CHECK(rows_short_of_face >= 2);
  // At the face the rod starts touching the entry face's particles.
  CHECK(at_face.history.column("bonds_broken")[1] > 0);
  INFO("bonds cut at entry 0 / 0.2 mm: " << at_face.summary["bonds_cut_by_needle"] << " / " << ahead.summary["bonds_cut_by_needle"]);
  CHECK(ahead.summary["bonds_cut_by_needle"].get<int>() < at_face.summary["bonds_cut_by_needle"].get<int>());
  CHECK(ahead.summary["energy_mJ"]["tissue_internal"].get<double>() < at_face.summary["energy_mJ"]["tissue_internal"].get<double>());
  for (const RunFiles* r : {&at_face, &ahead}) CHECK(r->summary["status"] == "finished");

  // A negative entry, or one the travel never reaches: one line, exit 2, no run folder.
  for (const auto& [flags, message] : {std::pair<std::string, std::string>{"--tissue-entry-x-mm -0.1", "--tissue-entry-x-mm -0.1: tissue.entry_x_mm must not be negative"},
                                       {"--tissue-entry-x-mm 0.8", "--tissue-entry-x-mm 0.8: tissue.entry_x_mm 0.8 mm is not less than the travel"}}) {
    const std::string out = refused_on_small_block("entry_bad", flags, message);
    CHECK(std::count(out.begin(), out.end(), '\n') == 1);
  }
}

TEST_CASE("tissue.separation.lip.mode: crushed to the scene depth by default, the whole lip, free or off on request, SB has no lip, bad input is refused",
          "[apps][lspg][gmsh][lip][slow]") {
  // HMB's tip point sits 0.80 mm above the rod's bottom: pushed 0.8 mm into the small block (0.4 mm particles), the particles
  // the tip passes below A inside the rod's outline are crushed by default (bonds kept), cut loose when free (every bond
  // cut), and left as they are when off. SB's tip point is on the rod's bottom: whatever the mode, its run is the same.
  const std::string hmb = R"("preset": "HMB")";
  const RunFiles off = run_sb_into_small_block("lip_off", "--set tissue.contact.lip_release_mode=off", hmb);
  const RunFiles crushed = run_sb_into_small_block("lip_crushed", "", hmb);
  const RunFiles whole = run_sb_into_small_block("lip_whole", "--set \"tissue.separation.lip.depth_mm=whole lip\"", hmb);
  const RunFiles free_band = run_sb_into_small_block("lip_free", "--set tissue.separation.lip.mode=free --set tissue.separation.lip.depth_mm=0.8", hmb);
  CHECK(off.scene["tissue"]["separation"]["lip"]["mode"] == "off");  // set in its older spelling (tissue.contact.lip_release_mode)
  CHECK(crushed.scene["tissue"]["separation"]["lip"]["mode"] == "crushed");
  CHECK(crushed.scene["tissue"]["separation"]["lip"]["depth_mm"].get<double>() == needle::kSceneCrushedLipDepthMm);
  CHECK(whole.scene["tissue"]["separation"]["lip"]["depth_mm"] == "whole lip");
  CHECK(free_band.scene["tissue"]["separation"]["lip"]["depth_mm"].get<double>() == 0.8);
  CHECK_FALSE(off.summary.contains("lip_release"));
  INFO("crushed " << crushed.summary["lip_release"].dump() << "; free " << free_band.summary["lip_release"].dump());
  for (const RunFiles* r : {&crushed, &whole, &free_band}) {
    const nlohmann::json& lip = r->summary["lip_release"];
    CHECK(lip["lip_thickness_mm"].get<double>() == Approx(0.80).margin(0.02));
    CHECK(lip["particles_released"].get<long>() > 0);
    CHECK(r->history.column("lip_particles_released").back() == lip["particles_released"].get<double>());
    CHECK(r->summary["status"] == "finished");
    CHECK(r->summary["energy_balance_error"].get<double>() < 0.02);
  }
  CHECK(crushed.summary["lip_release"]["bonds_cut"].get<long>() == 0);
  CHECK(crushed.summary["lip_release"]["depth_mm"].get<double>() == needle::kSceneCrushedLipDepthMm);
  CHECK(whole.summary["lip_release"]["depth_mm"] == "whole lip");
  // HMB's lip is 0.80 mm: the whole lip holds more particles than its top (the scene's depth, 0.48 mm).
  CHECK(whole.summary["lip_release"]["particles_released"].get<long>() > crushed.summary["lip_release"]["particles_released"].get<long>());
  CHECK(free_band.summary["lip_release"]["bonds_cut"].get<long>() > 0);
  CHECK(free_band.summary["bonds_broken"].get<long>() >=
        free_band.summary["lip_release"]["bonds_cut"].get<long>() + free_band.summary["bonds_cut_by_needle"].get<long>());
  CHECK(crushed.summary["deflection_mm"].get<double>() != off.summary["deflection_mm"].get<double>());

  const RunFiles sb_off = run_sb_into_small_block("lip_sb_off", "--set tissue.separation.lip.mode=off");
  const RunFiles sb_crushed = run_sb_into_small_block("lip_sb_crushed", "");
  CHECK_FALSE(sb_crushed.summary.contains("lip_release"));  // no lip, no model
  CHECK(sb_crushed.summary["deflection_mm"].get<double>() == sb_off.summary["deflection_mm"].get<double>());
  CHECK(sb_crushed.history.column("deflection_mm") == sb_off.history.column("deflection_mm"));

  // A depth that is not positive, a start above A, an unknown mode: one line, exit 2, no run folder.
  for (const auto& [flags, message] :
       {std::pair<std::string, std::string>{"--set tissue.separation.lip.depth_mm=0", "--set tissue.separation.lip.depth_mm=0: tissue.separation.lip.depth_mm"},
        {"--set tissue.separation.lip.below_mm=-0.1", "--set tissue.separation.lip.below_mm=-0.1: tissue.separation.lip.below_mm"},
        {"--set tissue.contact.lip_release_depth_mm=0", "--set tissue.contact.lip_release_depth_mm=0: tissue.separation.lip.depth_mm"},
        {"--set tissue.separation.lip.depth_mm=all", "give a depth in mm or \"whole lip\" (got \"all\")"},
        {"--set tissue.separation.lip.mode=dissolved", "must be crushed, free or off (got 'dissolved')"}}) {
    refused_in_one_line("lip_bad", flags, message);
  }
}

TEST_CASE("needle run refuses an absurd friction or drive speed by its flag, as the scene key does (issue 51)", "[apps][scene]") {
  for (const auto& [flags, message] :
       {std::pair<std::string, std::string>{"--tissue-friction 1e308", "--tissue-friction 1e308: tissue.friction must lie in [0, 2]"},
        {"--speed-m-per-s 1e308", "--speed-m-per-s 1e308: motion.speed_m_per_s must be positive and at most 100 m/s"},
        {"--set tissue.friction=5", "must lie in [0, 2]"},
        {"--set motion.speed_m_per_s=500", "at most 100 m/s"}}) {
    refused_in_one_line("physical_bad", flags, message);
  }
}
