#include "runs/scene_key_spellings.h"

#include <array>
#include <fmt/format.h>

#include "core/units.h"

namespace needle {

namespace {

struct Moved {
  const char* older;    // the key in tissue.contact, without its unit suffix
  const char* section;  // its section under tissue now
  const char* now;      // its name there, without its unit suffix
};

constexpr std::array<Moved, 10> kMoved = {{
    {"cuts_bonds", "separation", "needle_cut"},
    {"slit_half_height", "separation.slit", "half_height"},
    {"slit_lead", "separation.slit", "lead"},
    {"crack_reach", "separation.crack", "reach"},
    {"crack_angles", "separation.crack", "angles"},
    {"crack_lead", "separation.crack", "lead"},
    {"lip_release_mode", "separation.lip", "mode"},
    {"lip_release_below", "separation.lip", "below"},
    {"lip_release_depth", "separation.lip", "depth"},
    {"cutting_pressure", "cutting", "pressure"},
}};

}  // namespace

std::string key_quantity(const std::string& key) {
  for (Dimension d : {Dimension::length, Dimension::time, Dimension::speed, Dimension::stress, Dimension::density, Dimension::angle}) {
    const std::string suffix = canonical_suffix(d);
    if (key.size() > suffix.size() && key.compare(key.size() - suffix.size(), suffix.size(), suffix) == 0) return key.substr(0, key.size() - suffix.size());
  }
  return key;
}

std::optional<KeySpelling> current_contact_key(const std::string& contact_key) {
  // The key's unit suffix, if it has one, travels with it ("crack_reach_mm" -> "reach_mm", "crack_angles_deg" ->
  // "angles_deg"); a key written with a unit in its value has none ("crack_reach": "1 mm").
  const std::string base = key_quantity(contact_key), suffix = contact_key.substr(base.size());
  for (const Moved& m : kMoved)
    if (base == m.older) return KeySpelling{m.section, m.now + suffix, m.now};
  return std::nullopt;
}

std::string current_scene_key(const std::string& dotted_key) {
  const std::string contact = "tissue.contact.";
  if (dotted_key.rfind(contact, 0) != 0) return dotted_key;
  const std::optional<KeySpelling> now = current_contact_key(dotted_key.substr(contact.size()));
  return now ? "tissue." + now->section + "." + now->key : dotted_key;
}

std::string older_spelling_note(const std::string& where, const std::string& older_key, const std::string& current_key) {
  return fmt::format("{}: {} is read as {} (its place since 2026-11-28; docs/scenes.md)", where, older_key, current_key);
}

}  // namespace needle
