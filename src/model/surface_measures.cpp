#include "cosserat/model/surface_measures.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

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

QuantizedSum block_area(const Field<Vec3>& r, double quantum) {
  const Block& b = r.block();
  const int kend = std::min(b.k1, b.m - 1), lend = std::min(b.l1, b.n - 1);
  std::vector<QuantizedSum> row_area(static_cast<std::size_t>(std::max(lend - b.l0, 0)),
                                     QuantizedSum(quantum));
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < lend; ++l) {
    QuantizedSum sum(quantum);
    for (int k = b.k0; k < kend; ++k) {
      const Vec3 p = r(k, l), q = r(k + 1, l), s = r(k + 1, l + 1), t = r(k, l + 1);
      sum.add(0.5 * (norm(cross(q - p, s - p)) + norm(cross(s - p, t - p))));
    }
    row_area[static_cast<std::size_t>(l - b.l0)] = sum;
  }
  QuantizedSum area(quantum);
  for (const QuantizedSum& a : row_area) area.add(a);
  return area;
}

}  // namespace cosserat
