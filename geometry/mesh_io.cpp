#include "geometry/mesh_io.h"

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/config.h>
#include <assimp/scene.h>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <fmt/format.h>
#include <random>

#include "core/input_error.h"
#include "geometry/cad_solid.h"
#include "geometry/surface_measures.h"
#include "geometry/tag_colors.h"

namespace needle {
namespace fs = std::filesystem;

SurfaceFormat surface_format_from_path(const std::string& path, bool ascii_stl) {
  NEEDLE_REQUIRE(!fs::is_directory(path), fmt::format("'{}' is a folder: give the surface file's name, e.g. {}/tip.stl", path, path));
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  if (ext == ".stl") return ascii_stl ? SurfaceFormat::stl_ascii : SurfaceFormat::stl_binary;
  if (ext == ".obj") return SurfaceFormat::obj;
  if (ext == ".ply") return SurfaceFormat::ply;
  if (ext == ".glb") return SurfaceFormat::glb;
  if (ext == ".gltf") return SurfaceFormat::gltf;
  throw InputError(fmt::format("cannot tell the surface format of '{}': use .stl, .obj, .ply, .glb or .gltf", path));
}

std::string scratch_dir_beside(const std::string& path) {
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  NEEDLE_REQUIRE(fs::is_directory(dir), fmt::format("output folder '{}' does not exist", dir.string()));
  std::random_device random;
  const fs::path scratch = dir / fmt::format(".needle-partial-{:08x}", random());
  fs::create_directory(scratch);
  return scratch.string();
}

void commit_scratch_file(const std::string& scratch_dir, const std::string& name, const std::string& final_dir) {
  fs::rename(fs::path(scratch_dir) / name, fs::path(final_dir.empty() ? "." : final_dir) / name);
}

void write_file_atomically(const std::string& path, const std::function<void(const std::string& scratch_path)>& write) {
  const std::string scratch = scratch_dir_beside(path);
  try {
    const std::string name = fs::path(path).filename().string();
    write((fs::path(scratch) / name).string());
    commit_scratch_file(scratch, name, fs::path(path).parent_path().string());
  } catch (...) {
    fs::remove_all(scratch);
    throw;
  }
  fs::remove_all(scratch);
}

namespace {

// A vertex as the files store it: rounded to a nanometre grid, then to single precision. The grid welds corners
// the CAD left a few 1e-17 mm apart (which single precision keeps apart near 0): the sliver between them then has
// two equal corners and is left out whole, and its neighbours share the welded corner, so the surface stays closed.
Eigen::Vector3f written_position(const TriSurface& s, int vertex) {
  Eigen::Vector3d p = s.V.row(vertex).transpose();
  for (int k = 0; k < 3; ++k) p[k] = std::round(p[k] * 1e9) / 1e9;
  return p.cast<float>();
}

// One aiMesh per group of faces; the scene owns everything it points to.
aiMesh* make_mesh(const TriSurface& s, const std::vector<int>& faces, const std::string& name, unsigned material) {
  auto* mesh = new aiMesh;
  mesh->mName = aiString(name);
  mesh->mMaterialIndex = material;
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh->mNumVertices = static_cast<unsigned>(3 * faces.size());
  mesh->mVertices = new aiVector3D[mesh->mNumVertices];
  mesh->mNormals = new aiVector3D[mesh->mNumVertices];
  mesh->mNumFaces = static_cast<unsigned>(faces.size());
  mesh->mFaces = new aiFace[mesh->mNumFaces];
  for (size_t i = 0; i < faces.size(); ++i) {
    const int f = faces[i];
    const Eigen::Vector3d a = written_position(s, s.F(f, 0)).cast<double>(), b = written_position(s, s.F(f, 1)).cast<double>(),
                          c = written_position(s, s.F(f, 2)).cast<double>();
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() > 0) n.normalize();
    aiFace& face = mesh->mFaces[i];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3];
    for (int k = 0; k < 3; ++k) {
      const unsigned v = static_cast<unsigned>(3 * i + k);
      const Eigen::Vector3f p = written_position(s, s.F(f, k));
      mesh->mVertices[v] = aiVector3D(p.x(), p.y(), p.z());
      mesh->mNormals[v] = aiVector3D(static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z()));
      face.mIndices[k] = v;
    }
  }
  return mesh;
}

// Whether face f has no area once its corners are rounded to the files' single precision: a sliver whose
// corners meet or lie on one line (its angle below 1e-6 rad, where a reader's single-precision cross product
// can be zero), which readers take for a line or a point (assimp) or refuse. Such faces are not written.
bool degenerate_in_float(const TriSurface& s, int f) {
  Eigen::Vector3f p[3];
  for (int k = 0; k < 3; ++k) p[k] = written_position(s, s.F(f, k));
  const Eigen::Vector3f e1 = p[1] - p[0], e2 = p[2] - p[0];
  const Eigen::Vector3f cross = e1.cross(e2);  // as a reader computes it, in single precision
  const Eigen::Vector3d e1d = e1.cast<double>(), e2d = e2.cast<double>();
  return p[0] == p[1] || p[1] == p[2] || p[0] == p[2] || cross.squaredNorm() == 0 ||
         !(e1d.cross(e2d).norm() > 1e-6 * e1d.norm() * e2d.norm());
}

std::unique_ptr<aiScene> make_scene(const TriSurface& s, bool mesh_per_tag) {
  std::vector<std::vector<int>> groups;
  std::vector<std::string> names;
  if (mesh_per_tag) {
    groups.resize(s.tag_names.size());
    names = s.tag_names;
  } else {
    groups.resize(1);
    names = {"needle"};
  }
  for (int f = 0; f < s.num_faces(); ++f)
    if (!degenerate_in_float(s, f)) groups[mesh_per_tag && s.face_tag.size() ? s.face_tag(f) : 0].push_back(f);
  auto scene = std::make_unique<aiScene>();
  std::vector<aiMesh*> meshes;
  std::vector<aiMaterial*> materials;
  for (size_t g = 0; g < groups.size(); ++g) {
    if (groups[g].empty()) continue;
    auto* material = new aiMaterial;
    aiString material_name(names[g]);
    material->AddProperty(&material_name, AI_MATKEY_NAME);
    const std::array<unsigned char, 3> rgb = tag_color(names[g]);
    aiColor3D color(rgb[0] / 255.f, rgb[1] / 255.f, rgb[2] / 255.f);
    material->AddProperty(&color, 1, AI_MATKEY_COLOR_DIFFUSE);
    meshes.push_back(make_mesh(s, groups[g], names[g], static_cast<unsigned>(materials.size())));
    materials.push_back(material);
  }
  scene->mNumMeshes = static_cast<unsigned>(meshes.size());
  scene->mMeshes = new aiMesh*[meshes.size()];
  std::copy(meshes.begin(), meshes.end(), scene->mMeshes);
  scene->mNumMaterials = static_cast<unsigned>(materials.size());
  scene->mMaterials = new aiMaterial*[materials.size()];
  std::copy(materials.begin(), materials.end(), scene->mMaterials);
  scene->mRootNode = new aiNode("needle");
  scene->mRootNode->mNumMeshes = scene->mNumMeshes;
  scene->mRootNode->mMeshes = new unsigned[scene->mNumMeshes];
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) scene->mRootNode->mMeshes[m] = m;
  return scene;
}

// What assimp writes, made readable by the other common readers (meshio, VTK): its ASCII STL puts a blank line after
// every facet and names the solid "AssimpScene"; its PLY names the face list "vertex_index" where the format's own
// examples, VTK and meshio read "vertex_indices"; its OBJ carries smoothed normals under indices of their own
// ("f 1//1 2//2 3//3", fewer normals than vertices), which readers that take one normal per vertex (meshio) refuse:
// the OBJ is written without normals (a facet's normal is its triangle's).
void make_readable_by_others(const std::string& file, SurfaceFormat format) {
  if (format != SurfaceFormat::stl_ascii && format != SurfaceFormat::ply && format != SurfaceFormat::obj) return;
  std::string data;
  {
    std::ifstream in(file, std::ios::binary);
    data.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  std::string fixed;
  if (format == SurfaceFormat::obj) {
    std::istringstream lines(data);
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind("vn ", 0) == 0) continue;
      if (line.rfind("f ", 0) == 0) {  // "f  1//1 2//2 3//3" -> "f 1 2 3"
        std::istringstream corners(line.substr(2));
        line = "f";
        for (std::string corner; corners >> corner;) line += " " + corner.substr(0, corner.find('/'));
      }
      fixed += line + "\n";
    }
  } else if (format == SurfaceFormat::stl_ascii) {
    fixed.reserve(data.size());
    std::istringstream lines(data);
    for (std::string line; std::getline(lines, line);) {
      if (line.empty()) continue;
      if (line == "solid AssimpScene") line = "solid needle";
      if (line == "endsolid AssimpScene") line = "endsolid needle";
      fixed += line + "\n";
    }
  } else {
    const size_t end = data.find("end_header\n");
    NEEDLE_REQUIRE(end != std::string::npos, fmt::format("'{}': a PLY file without its header's end", file));
    std::string header = data.substr(0, end);
    const std::string old_name = " vertex_index\n";
    const size_t at = header.find(old_name);
    if (at != std::string::npos) header.replace(at, old_name.size(), " vertex_indices\n");
    fixed = header + data.substr(end);
  }
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << fixed;
  if (!out.good()) throw std::runtime_error(fmt::format("could not write '{}'", file));
}

}  // namespace

std::vector<std::string> write_surface(const TriSurface& surface, const std::string& path, SurfaceFormat format) {
  NEEDLE_REQUIRE(surface.num_faces() > 0, "refusing to write an empty surface");
  const char* id = nullptr;
  bool per_tag = false;
  std::vector<std::string> sidecars;
  const fs::path target(path);
  switch (format) {
    case SurfaceFormat::stl_binary: id = "stlb"; break;
    case SurfaceFormat::stl_ascii: id = "stl"; break;
    case SurfaceFormat::ply: id = "plyb"; break;
    case SurfaceFormat::obj: id = "obj"; per_tag = true; sidecars.push_back(target.stem().string() + ".mtl"); break;
    case SurfaceFormat::glb: id = "glb2"; per_tag = true; break;
    case SurfaceFormat::gltf: id = "gltf2"; per_tag = true; sidecars.push_back(target.stem().string() + ".bin"); break;
  }
  const std::unique_ptr<aiScene> scene = make_scene(surface, per_tag);
  const std::string scratch = scratch_dir_beside(path);
  const std::string name = target.filename().string();
  Assimp::Exporter exporter;
  if (exporter.Export(scene.get(), id, (fs::path(scratch) / name).string()) != AI_SUCCESS) {
    fs::remove_all(scratch);
    throw std::runtime_error(fmt::format("could not write '{}': {}", path, exporter.GetErrorString()));
  }
  std::vector<std::string> written;
  try {
    make_readable_by_others((fs::path(scratch) / name).string(), format);
    for (const std::string& file : sidecars)
      if (fs::exists(fs::path(scratch) / file)) {
        commit_scratch_file(scratch, file, target.parent_path().string());
        written.push_back((target.parent_path() / file).string());
      }
    commit_scratch_file(scratch, name, target.parent_path().string());
  } catch (...) {
    fs::remove_all(scratch);
    throw;
  }
  written.push_back(path);
  fs::remove_all(scratch);
  return written;
}

TriSurface read_surface(const std::string& path) {
  NEEDLE_REQUIRE(fs::is_regular_file(path), fmt::format("cannot read '{}': no such file", path));
  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS | aiComponent_TEXCOORDS | aiComponent_COLORS);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_RemoveComponent | aiProcess_JoinIdenticalVertices | aiProcess_Triangulate);
  NEEDLE_REQUIRE(scene && scene->mNumMeshes > 0,
                 fmt::format("cannot read '{}' as a surface: {}", path,
                             scene ? "it holds no mesh" : importer.GetErrorString()));
  TriSurface surface;
  std::vector<Eigen::Vector3d> V;
  std::vector<Eigen::Vector3i> F;
  std::vector<int> tags;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    std::string name = mesh->mName.length ? mesh->mName.C_Str() : "";
    if (mesh->mMaterialIndex < scene->mNumMaterials) {
      aiString material_name;
      if (scene->mMaterials[mesh->mMaterialIndex]->Get(AI_MATKEY_NAME, material_name) == AI_SUCCESS &&
          material_name.length && std::string(material_name.C_Str()) != "DefaultMaterial")
        name = material_name.C_Str();
    }
    if (name.empty()) name = "surface";
    int tag = surface.tag_index(name);
    if (tag < 0) {
      surface.tag_names.push_back(name);
      tag = static_cast<int>(surface.tag_names.size()) - 1;
    }
    const int offset = static_cast<int>(V.size());
    for (unsigned v = 0; v < mesh->mNumVertices; ++v)
      V.emplace_back(mesh->mVertices[v].x, mesh->mVertices[v].y, mesh->mVertices[v].z);
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines are not part of a surface
      F.emplace_back(face.mIndices[0] + offset, face.mIndices[1] + offset, face.mIndices[2] + offset);
      tags.push_back(tag);
    }
  }
  NEEDLE_REQUIRE(!F.empty(), fmt::format("'{}' holds no triangles", path));
  surface.V.resize(V.size(), 3);
  for (size_t i = 0; i < V.size(); ++i) surface.V.row(i) = V[i].transpose();
  surface.F.resize(F.size(), 3);
  for (size_t i = 0; i < F.size(); ++i) surface.F.row(i) = F[i].transpose();
  surface.face_tag = Eigen::Map<Eigen::VectorXi>(tags.data(), tags.size());
  surface = weld_identical_vertices(surface);
  const TopologyCheck topology = check_topology(surface);
  NEEDLE_REQUIRE(topology.closed_manifold(),
                 fmt::format("'{}' is not a closed, consistently oriented manifold surface: {}", path,
                             topology.describe()));
  NEEDLE_REQUIRE(enclosed_volume_mm3(surface) > 0,
                 fmt::format("'{}' encloses no positive volume: its triangles face inward", path));
  NEEDLE_REQUIRE(!surface_self_intersects(surface),
                 fmt::format("'{}' intersects itself (triangles of it cross): it bounds no single solid, so its volume and "
                             "sections would mean nothing and it cannot be meshed", path));
  return surface;
}

}  // namespace needle
