#include "cosserat/model/surface_measures.hpp"

#include <cmath>

#include "surface_geometry.hpp"

namespace cosserat {

// √a = |a₁ × a₂|, which round-off cannot make the root of a negative number as it can
// a₁₁a₂₂ − a₁₂² for a collapsed element.
void area_ratio(const Field<Vec3>& r, double h1, double h2, const Sym2& rest_metric,
                Field<double>& ratio) {
  using namespace geometry;
  const Block& b = r.block();
  const double rest_root =
      std::sqrt(rest_metric[0] * rest_metric[2] - rest_metric[1] * rest_metric[1]);
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) {
      const Tangents t = tangents(r, k, l, neighbours(b, k, l), h1, h2);
      ratio(k, l) = norm(cross(t.a1, t.a2)) / rest_root;
    }
}

void mean_curvature(const Field<Vec3>& r, double h1, double h2, Field<double>& curvature) {
  using namespace geometry;
  const Block& b = r.block();
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) {
      const Neighbours p = neighbours(b, k, l);
      const Sym2 upper = metric(tangents(r, k, l, p, h1, h2)).upper;
      const Sym2 bend =
          geometry::curvature(unit_normal(r, k, l, p), second_derivatives(r, k, l, p, h1, h2));
      curvature(k, l) =
          0.5 * (upper[0] * bend[0] + 2.0 * upper[1] * bend[1] + upper[2] * bend[2]);
    }
}

}  // namespace cosserat
