#pragma once
// Surface files through assimp: STL (binary, ASCII), OBJ (+ .mtl), PLY, glTF 2 (.glb, .gltf + .bin).
// OBJ and glTF keep one mesh per facet tag, named after it, so the tags survive the round trip.
#include <functional>
#include <string>
#include <vector>

#include "geometry/tri_surface.h"

namespace needle {

enum class SurfaceFormat { stl_binary, stl_ascii, obj, ply, glb, gltf };

// Picks the format from the file extension (.stl .obj .ply .glb .gltf); InputError otherwise.
SurfaceFormat surface_format_from_path(const std::string& path, bool ascii_stl = false);

// Writes the surface; every file appears complete or not at all (written in a scratch folder
// beside the target, then renamed). Returns the paths written (OBJ and glTF also write a sidecar).
std::vector<std::string> write_surface(const TriSurface& surface, const std::string& path, SurfaceFormat format);

// Reads a surface file, welds identical vertices and checks that it is a closed, consistently
// oriented manifold; InputError with the reason otherwise. Mesh names become facet tags.
TriSurface read_surface(const std::string& path);

// Small helpers for apps that write other files the same all-or-nothing way.
std::string scratch_dir_beside(const std::string& path);
void commit_scratch_file(const std::string& scratch_dir, const std::string& name, const std::string& final_dir);

// Calls write(scratch_path) to write one file in a scratch folder beside `path`, then renames it to
// `path`; if write throws, nothing is left behind.
void write_file_atomically(const std::string& path, const std::function<void(const std::string& scratch_path)>& write);

}  // namespace needle
