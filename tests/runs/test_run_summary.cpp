// The readers' view of a run's summary.json (runs/run_summary.h): the sample length I_s by today's measure, from
// summaries written today and before it changed.
#include <catch2/catch.hpp>
#include <cmath>
#include <nlohmann/json.hpp>

#include "core/input_error.h"
#include "runs/run_summary.h"

using namespace needle;
using nlohmann::json;

TEST_CASE("A summary's I_s is the floor its nearest layer covers, in today's summaries and in older ones", "[runs][cannula]") {
  // Today's: I_s_mm with its measure named.
  const json today = {{"I_s_mm", 15.2}, {"I_s_measure", "floor_layer_covered_mm"}, {"floor_layer_covered_mm", 15.2}, {"floor_length_mm", 21.0}};
  CHECK(sample_I_s_mm(today) == 15.2);
  // Before 2026-11-29: I_s_mm held the contact's extent; the layer's covered length is read instead.
  const json before = {{"I_s_mm", 0.98}, {"floor_layer_covered_mm", 15.1}, {"floor_length_mm", 0.98}};
  CHECK(sample_I_s_mm(before) == 15.1);
  // Older still, without the layer: no I_s by today's measure.
  CHECK(std::isnan(sample_I_s_mm(json{{"I_s_mm", 12.0}})));
  // A measure this build does not know is refused, not read as another.
  CHECK_THROWS_AS(sample_I_s_mm(json{{"I_s_mm", 12.0}, {"I_s_measure", "contact_extent"}}), InputError);
  // The whole outcome: I_s and, beside it, the contact's extent; none without a sample.
  const RunOutcome o = run_outcome({{"status", "finished"}, {"sample", before}});
  CHECK(o.sample_I_s_mm == 15.1);
  CHECK(o.sample_contact_extent_mm == 0.98);
  CHECK(std::isnan(run_outcome({{"status", "finished"}}).sample_I_s_mm));
}
