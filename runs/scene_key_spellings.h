#pragma once
// Where a scene key lives today. Until 2026-11-28 scenes wrote the separation models' keys and the cutting pressure in
// the tissue's contact section, with a prefix (tissue.contact.crack_reach_mm); they now live in sections that mirror
// the structs they fill (tissue.separation.crack.reach_mm, runs/scene.h). The older spellings are still read, with a
// note, so that stored scenes, sweeps and studies load as they were written.
#include <optional>
#include <string>

namespace needle {

struct KeySpelling {
  std::string section;  // under tissue: "separation.crack"
  std::string key;      // the key there, with the unit suffix the older spelling had: "reach_mm"
  std::string quantity;  // the key without a unit suffix: "reach"
};

// A key without its unit suffix: the quantity it names. "travel_mm" and "travel" name one quantity; "stabilization"
// and "stabilization_coefficient" name two.
std::string key_quantity(const std::string& key);

// The current place of a key of the tissue's contact section written the older way ("crack_reach_mm", "cuts_bonds",
// "lip_release_depth"), or nothing for a key that is the contact's own.
std::optional<KeySpelling> current_contact_key(const std::string& contact_key);

// A dotted scene key in today's spelling: "tissue.contact.crack_reach_mm" -> "tissue.separation.crack.reach_mm"; any
// other key as it is.
std::string current_scene_key(const std::string& dotted_key);

// The note left for a key read in its older spelling: "where: tissue.contact.X is read as tissue.S.Y (...)" (dotted keys).
std::string older_spelling_note(const std::string& where, const std::string& older_key, const std::string& current_key);

}  // namespace needle
