#pragma once
// One fixed colour per facet name, shared by the PNG renderer and the OBJ/glTF materials.
#include <array>
#include <string>

namespace needle {
std::array<unsigned char, 3> tag_color(const std::string& tag_name);
}
