#include "mesher/gmsh_model_mesh.h"

#include <gmsh.h>

#include <numeric>
#include <stdexcept>
#include <unordered_map>

namespace needle::detail {
namespace {

// gmsh element types: 2 = 3-node triangle, 9 = 6-node triangle, 4 = 4-node tet, 11 = 10-node tet.
int tet_type(int order) { return order == 2 ? 11 : 4; }
int triangle_type(int order) { return order == 2 ? 9 : 2; }

// gmsh numbers the last two mid-edge nodes of a 10-node tet (2,3), (1,3); VTK the other way round.
constexpr int kGmshToVtkTet10[10] = {0, 1, 2, 3, 4, 5, 6, 7, 9, 8};

}  // namespace

TetMesh extract_tet_mesh(int order, const std::map<int, int>& surface_tag, const std::vector<std::string>& tag_names) {
  TetMesh mesh;
  mesh.order = order;
  mesh.tag_names = tag_names;

  std::vector<std::size_t> node_tags;
  std::vector<double> coords, parametric;
  gmsh::model::mesh::getNodes(node_tags, coords, parametric, -1, -1, true, false);
  std::unordered_map<std::size_t, int> index;
  index.reserve(node_tags.size());
  mesh.X.resize(static_cast<Eigen::Index>(node_tags.size()), 3);
  for (size_t i = 0; i < node_tags.size(); ++i) {
    index[node_tags[i]] = static_cast<int>(i);
    mesh.X.row(static_cast<Eigen::Index>(i)) << coords[3 * i], coords[3 * i + 1], coords[3 * i + 2];
  }
  auto node = [&](std::size_t tag) {
    const auto it = index.find(tag);
    if (it == index.end()) throw std::runtime_error("mesh: an element refers to a node that does not exist");
    return it->second;
  };

  std::vector<std::size_t> element_tags, element_nodes;
  gmsh::model::mesh::getElementsByType(tet_type(order), element_tags, element_nodes, -1);
  if (element_nodes.size() != element_tags.size() * (order == 2 ? 10 : 4))
    throw std::runtime_error("mesh: the model holds no tetrahedra of order " + std::to_string(order));
  const int per_tet = order == 2 ? 10 : 4;
  mesh.T.resize(static_cast<Eigen::Index>(element_tags.size()), per_tet);
  for (size_t t = 0; t < element_tags.size(); ++t)
    for (int c = 0; c < per_tet; ++c)
      mesh.T(static_cast<Eigen::Index>(t), order == 2 ? kGmshToVtkTet10[c] : c) = node(element_nodes[per_tet * t + c]);

  const int per_face = order == 2 ? 6 : 3;
  std::vector<std::array<int, 7>> faces;  // nodes + tag
  for (const auto& [entity, tag] : surface_tag) {
    // getElements by entity: getElementsByType(type, ..., tag) ignores the tag in gmsh 4.8.4.
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> tags_by_type, nodes_by_type;
    gmsh::model::mesh::getElements(types, tags_by_type, nodes_by_type, 2, entity);
    for (size_t k = 0; k < types.size(); ++k) {
      if (types[k] != triangle_type(order))
        throw std::runtime_error("mesh: surface elements of an unexpected type (gmsh type " + std::to_string(types[k]) + ")");
      for (size_t f = 0; f < tags_by_type[k].size(); ++f) {
        std::array<int, 7> row{};
        for (int c = 0; c < per_face; ++c) row[c] = node(nodes_by_type[k][per_face * f + c]);
        row[6] = tag;
        faces.push_back(row);
      }
    }
  }
  mesh.boundary_faces.resize(static_cast<Eigen::Index>(faces.size()), per_face);
  mesh.boundary_tag.resize(static_cast<Eigen::Index>(faces.size()));
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int c = 0; c < per_face; ++c) mesh.boundary_faces(static_cast<Eigen::Index>(f), c) = faces[f][c];
    mesh.boundary_tag(static_cast<Eigen::Index>(f)) = faces[f][6];
  }
  drop_unused_nodes(mesh);
  orient_tet_mesh(mesh);
  return mesh;
}

void load_tet_mesh(const TetMesh& mesh) {
  const int n_tags = static_cast<int>(mesh.tag_names.size());
  std::vector<int> surfaces;
  for (int tag = 0; tag < n_tags; ++tag) {
    if ((mesh.boundary_tag.array() == tag).any()) surfaces.push_back(tag + 1);
  }
  for (int s : surfaces) gmsh::model::addDiscreteEntity(2, s);
  gmsh::model::addDiscreteEntity(3, 1, surfaces);

  std::vector<std::size_t> node_tags(static_cast<size_t>(mesh.num_nodes()));
  std::iota(node_tags.begin(), node_tags.end(), std::size_t{1});
  std::vector<double> coords(3 * node_tags.size());
  for (int i = 0; i < mesh.num_nodes(); ++i)
    for (int k = 0; k < 3; ++k) coords[3 * i + k] = mesh.X(i, k);
  gmsh::model::mesh::addNodes(3, 1, node_tags, coords);

  const int per_tet = mesh.nodes_per_tet();
  std::vector<std::size_t> element_tags(static_cast<size_t>(mesh.num_tets()));
  std::iota(element_tags.begin(), element_tags.end(), std::size_t{1});
  std::vector<std::size_t> element_nodes(element_tags.size() * per_tet);
  for (int t = 0; t < mesh.num_tets(); ++t)
    for (int c = 0; c < per_tet; ++c)
      element_nodes[per_tet * t + c] = static_cast<std::size_t>(mesh.T(t, mesh.order == 2 ? kGmshToVtkTet10[c] : c)) + 1;
  gmsh::model::mesh::addElementsByType(1, tet_type(mesh.order), element_tags, element_nodes);

  std::size_t next_element = element_tags.size() + 1;
  const int per_face = mesh.nodes_per_face();
  for (int s : surfaces) {
    std::vector<std::size_t> face_tags, face_nodes;
    for (int f = 0; f < mesh.num_boundary_faces(); ++f) {
      if (mesh.boundary_tag(f) != s - 1) continue;
      face_tags.push_back(next_element++);
      for (int c = 0; c < per_face; ++c) face_nodes.push_back(static_cast<std::size_t>(mesh.boundary_faces(f, c)) + 1);
    }
    gmsh::model::mesh::addElementsByType(s, triangle_type(mesh.order), face_tags, face_nodes);
    gmsh::model::addPhysicalGroup(2, {s}, s);
    gmsh::model::setPhysicalName(2, s, mesh.tag_names[static_cast<size_t>(s - 1)]);
  }
  gmsh::model::addPhysicalGroup(3, {1}, 1);
  gmsh::model::setPhysicalName(3, 1, "needle");
}

}  // namespace needle::detail
