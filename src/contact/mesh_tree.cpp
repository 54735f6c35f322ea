// Closest points and inside tests of a mesh solid through CGAL (docs/contact.md,
// "Solids and their motion": a maintained bounding-volume tree, not a hand-written search). The
// only file that includes CGAL.
//
// Kernel: exact predicates, inexact constructions. The inside test counts a ray's crossings of
// the triangles; with plain doubles an orientation test near an edge or vertex can count one
// crossing twice or none and flip inside and outside. Filtered predicates are exact at the
// price of interval arithmetic, and only near-degenerate cases fall back to GMP. The closest
// point is a construction, so doubles suffice there.

#include "mesh_tree.hpp"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace cosserat {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Surface = CGAL::Surface_mesh<Point>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, CGAL::AABB_face_graph_triangle_primitive<Surface>>>;
using Inside = CGAL::Side_of_triangle_mesh<Surface, Kernel, CGAL::Default, Tree>;

Surface to_surface(const TriangleMesh& mesh) {
  Surface surface;
  std::vector<Surface::Vertex_index> vertex;
  vertex.reserve(mesh.vertices.size());
  for (const Vec3& v : mesh.vertices) vertex.push_back(surface.add_vertex(Point(v.x, v.y, v.z)));
  const auto count = static_cast<int>(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& [a, b, c] = mesh.triangles[i];
    if (a < 0 || b < 0 || c < 0 || a >= count || b >= count || c >= count) {
      throw std::invalid_argument("mesh solid: triangle " + std::to_string(i) +
                                  " has a vertex index out of range");
    }
    if (surface.add_face(vertex[a], vertex[b], vertex[c]) == Surface::null_face()) {
      throw std::invalid_argument("mesh solid: triangle " + std::to_string(i) +
                                  " makes the surface non-manifold or inconsistently oriented");
    }
  }
  if (!CGAL::is_closed(surface)) {
    throw std::invalid_argument("mesh solid: the surface is not closed, so it has no inside");
  }
  return surface;
}

}  // namespace

struct SolidGeometry::MeshTree::Cgal {
  explicit Cgal(const TriangleMesh& mesh)
      : surface(to_surface(mesh)), tree(faces(surface).first, faces(surface).second, surface),
        inside(prepare(tree)) {
    // Face indices of a Surface_mesh built by add_face follow the order of the faces added.
    face_normal.reserve(mesh.triangles.size());
    for (const auto& [a, b, c] : mesh.triangles) {
      const Vec3 n = cross(mesh.vertices[b] - mesh.vertices[a], mesh.vertices[c] - mesh.vertices[a]);
      const double length = norm(n);
      face_normal.push_back(length > 0.0 ? n / length : Vec3{0.0, 0.0, 1.0});
    }
  }

  // Both search structures built now rather than lazily on a first query, so every later query
  // only reads and threads share the tree without locks.
  static const Tree& prepare(Tree& tree) {
    tree.build();
    tree.accelerate_distance_queries();
    return tree;
  }

  Surface surface;  // the tree points into it
  Tree tree;
  Inside inside;
  std::vector<Vec3> face_normal;
};

SolidGeometry::MeshTree::MeshTree(const TriangleMesh& mesh) : cgal(std::make_unique<const Cgal>(mesh)) {}

SolidGeometry::MeshTree::~MeshTree() = default;

Closest SolidGeometry::MeshTree::closest(const Vec3& p) const {
  const Point query(p.x, p.y, p.z);
  const auto [nearest, face] = cgal->tree.closest_point_and_primitive(query);
  const CGAL::Bounded_side side = cgal->inside(query);
  const Vec3 offset = p - Vec3{nearest.x(), nearest.y(), nearest.z()};
  const double distance = norm(offset);
  if (side == CGAL::ON_BOUNDARY || distance == 0.0) {
    return {0.0, cgal->face_normal[static_cast<std::size_t>(face)]};
  }
  const double sign = side == CGAL::ON_BOUNDED_SIDE ? -1.0 : 1.0;
  return {sign * distance, (sign / distance) * offset};
}

}  // namespace cosserat
