#pragma once
// The queries of a mesh solid, answered in mesh_tree.cpp by CGAL, which no other file of the
// project includes (its headers cost seconds of compile time per file).

#include <memory>

#include "cosserat/contact/geometry.hpp"

namespace cosserat {

struct SolidGeometry::MeshTree {
  explicit MeshTree(const TriangleMesh& mesh);
  ~MeshTree();
  Closest closest(const Vec3& p) const;

  struct Cgal;
  std::unique_ptr<const Cgal> cgal;
};

}  // namespace cosserat
