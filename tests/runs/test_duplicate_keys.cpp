// A key given twice in one JSON object is refused in every file the toolkit reads (scenes, recipes, tissue
// cards, summaries), naming the key (and, in scenes, both lines): nlohmann keeps the last one without a word.
// A scene nested thousands of levels deep is refused at once, at its line.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>
#include <sys/stat.h>

#include "core/input_error.h"
#include "core/input_file.h"
#include "runs/json_file.h"
#include "runs/material_json.h"
#include "runs/recipe_json.h"
#include "runs/scene.h"

namespace {

std::string refusal(const std::function<void()>& read) {
  try {
    read();
  } catch (const needle::InputError& e) {
    return e.what();
  }
  return "accepted";
}

std::string file_with(const std::string& name, const std::string& text) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path.string();
}

}  // namespace

TEST_CASE("A key given twice in one object is refused in scenes, recipes, tissue cards and result files", "[apps][scene]") {
  CHECK(refusal([] { needle::parse_scene("{\n \"motion\": {\"travel_mm\": 3,\n  \"travel_mm\": 5}\n}\n", "dup.json"); }) ==
        "dup.json:3: motion.travel_mm: duplicate key (also on line 2; a key may be given once)");
  // The same key in two objects is two keys.
  CHECK(refusal([] { needle::parse_scene(R"({"motion": {"travel_mm": 3}, "cannula": {"enabled": true}, "tissue": {"enabled": true}})", "ok.json"); }) ==
        "accepted");
  const std::string recipe = file_with("needle_dup_recipe.json", R"({"name": "x", "rod": {"diameter_mm": 1.27, "diameter_mm": 1.0}})");
  CHECK(refusal([&] { needle::read_recipe_file(recipe); }) == recipe + ": duplicate key 'rod.diameter_mm' (a key may be given once in its object)");
  const std::string card = file_with("needle_dup_card.json", R"({"E_MPa": 0.1, "E_MPa": 0.2})");
  CHECK(refusal([&] { needle::read_material_file(card); }).find("duplicate key 'E_MPa'") != std::string::npos);
  const std::string summary = file_with("needle_dup_summary.json", R"({"runs": [{"a": 1}, {"a": 2, "a": 3}]})");
  CHECK(refusal([&] { needle::read_json_file(summary, "summary"); }).find("duplicate key 'runs.a'") != std::string::npos);
}

TEST_CASE("A scene nested deeper than 64 levels is refused at once, a real scene's depth is not", "[apps][scene]") {
  const auto nested = [](int depth) {
    std::string text;
    for (int k = 0; k < depth; ++k) text += "{\"a\":";
    text += "1";
    for (int k = 0; k < depth; ++k) text += "}";
    return text;
  };
  // 50 000 levels: refused on reaching the 65th (it took 18 s to get to the unknown key before, building paths).
  CHECK(refusal([&] { needle::parse_scene(nested(50000), "deep.json"); }) == "deep.json:1: nested deeper than 64 levels (scenes and recipes nest a few)");
  // At 64 the parser reads on and the scene reader names the unknown key.
  CHECK(refusal([&] { needle::parse_scene(nested(64), "deep.json"); }).find("a: unknown key") != std::string::npos);
}

TEST_CASE("A folder named as a scene, a card or a result file is refused in the project's words", "[apps][scene]") {
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "needle_folder_not_file.json";
  std::filesystem::create_directories(folder);
  CHECK(refusal([&] { needle::read_scene(folder.string()); }) == "cannot read the JSON file '" + folder.string() + "': it is a folder, not a file");
  CHECK(refusal([&] { needle::read_material_file(folder.string()); }).find("it is a folder, not a file") != std::string::npos);
  CHECK(refusal([&] { needle::read_json_file(folder.string(), "summary"); }) ==
        "cannot read the summary '" + folder.string() + "': it is a folder, not a file");
  std::filesystem::remove_all(folder);
}

TEST_CASE("A device, a pipe or an oversized file named as a scene, a recipe, a card or a table is refused at once, before it is read",
          "[apps][scene]") {
  // /dev/zero was read until memory ran out; a pipe with no writer would block for ever.
  CHECK(refusal([] { needle::read_scene("/dev/zero"); }) == "cannot read the JSON file '/dev/zero': it is not a regular file (a device, pipe or socket)");
  CHECK(refusal([] { needle::read_recipe_file("/dev/zero"); }).find("it is not a regular file") != std::string::npos);
  CHECK(refusal([] { needle::read_material_file("/dev/zero"); }).find("it is not a regular file") != std::string::npos);
  CHECK(refusal([] { needle::read_json_file("/dev/zero", "summary"); }).find("it is not a regular file") != std::string::npos);
  const std::filesystem::path fifo = std::filesystem::temp_directory_path() / "needle_fifo_not_file.json";
  std::filesystem::remove(fifo);
  REQUIRE(mkfifo(fifo.c_str(), 0600) == 0);
  CHECK(refusal([&] { needle::read_scene(fifo.string()); }).find("it is not a regular file") != std::string::npos);
  std::filesystem::remove(fifo);
  // A sparse file past the limit: refused by its size, not read.
  const std::filesystem::path big = std::filesystem::temp_directory_path() / "needle_big_scene.json";
  { std::ofstream(big) << "{}"; }
  std::filesystem::resize_file(big, needle::kMaxInputFileBytes + 1);
  CHECK(refusal([&] { needle::read_scene(big.string()); }) ==
        "cannot read the JSON file '" + big.string() + "': it holds 67108865 bytes, more than the 64 MiB such a file may hold");
  std::filesystem::resize_file(big, 2);  // at the limit or below, read as before
  CHECK(refusal([&] { needle::read_scene(big.string()); }) == "accepted");
  std::filesystem::remove(big);
}

TEST_CASE("A JSON error reads in the project's words, without the parser's exception tag", "[apps][scene]") {
  CHECK(refusal([] { needle::parse_scene("{\"motion\": {\"travel_mm\": 1e999}}", "ovf.json"); }) ==
        "ovf.json:1: not valid JSON (number overflow parsing '1e999')");
  const std::string recipe = file_with("needle_bad_recipe.json", "{\"name\": \"x\",, }");
  const std::string words = refusal([&] { needle::read_recipe_file(recipe); });
  CHECK(words.rfind(recipe + ": not valid JSON: parse error at line 1", 0) == 0);
  CHECK(words.find("json.exception") == std::string::npos);
}
