#include "geometry/tag_colors.h"

#include <functional>
#include <map>

namespace needle {

std::array<unsigned char, 3> tag_color(const std::string& name) {
  static const std::map<std::string, std::array<unsigned char, 3>> palette = {
      {"top", {230, 120, 30}},        {"bottom", {40, 110, 220}},      {"side_pos", {40, 170, 80}},
      {"side_neg", {20, 160, 170}},   {"lancet_pos", {150, 70, 200}},  {"lancet_neg", {210, 70, 160}},
      {"groove_floor", {235, 200, 40}}, {"groove_wall", {150, 95, 50}}, {"shaft", {185, 188, 195}},
      {"base", {110, 110, 115}},      {"symmetry", {240, 150, 150}},
  };
  const auto it = palette.find(name);
  if (it != palette.end()) return it->second;
  const size_t h = std::hash<std::string>{}(name);
  return {static_cast<unsigned char>(60 + h % 180), static_cast<unsigned char>(60 + (h >> 8) % 180),
          static_cast<unsigned char>(60 + (h >> 16) % 180)};
}

}  // namespace needle
