// The energy forms (docs/equations.md, "Energy quadrature", in both quadratures): the force is
// the exact negative gradient of the energy, the energy is that of the discrete strains, and a
// damped run never gains energy.

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "cosserat/baseline/semi_implicit.hpp"
#include "cosserat/model/cosserat_energy.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

struct Sheet {
  Scene scene;
  Block block;
  Field<Vec3> r;
  CosseratEnergy energy;

  explicit Sheet(const Scene& s, Quadrature q = Quadrature::trapezoidal)
      : scene(s),
        block(Block::whole(s.m, s.n, MPI_COMM_SELF)),
        r(block),
        energy(block, s.h1(), s.h2(), flat_rest_state(s.material, s.u, s.v), q) {
    for (int l = 0; l < s.n; ++l)
      for (int k = 0; k < s.m; ++k) r(k, l) = testing::deformed(s, k, l);
  }
  double total() const { return energy.block_energy(r); }
};

// Sets r at a block's owned nodes and at its ghosts that lie in the grid, from position(k, l).
template <class Position>
void fill_with_ghosts(const Block& b, Field<Vec3>& r, Position position) {
  for (int l = std::max(b.l0 - b.ghost, 0); l < std::min(b.l1 + b.ghost, b.n); ++l)
    for (int k = std::max(b.k0 - b.ghost, 0); k < std::min(b.k1 + b.ghost, b.m); ++k)
      r(k, l) = position(k, l);
}

// −∂E/∂r_c at node (k, l) by a central difference of the sheet's energy with the given step.
double minus_difference(Sheet& sheet, int k, int l, int c, double step) {
  const double kept = sheet.r(k, l)[c];
  sheet.r(k, l)[c] = kept + step;
  const double up = sheet.total();
  sheet.r(k, l)[c] = kept - step;
  const double down = sheet.total();
  sheet.r(k, l)[c] = kept;
  return -(up - down) / (2.0 * step);
}

// The forces with component c of node (k, l) moved by +step into `up` and by −step into `down`.
void forces_either_side(Sheet& sheet, int k, int l, int c, double step, Field<Vec3>& up,
                        Field<Vec3>& down) {
  const double kept = sheet.r(k, l)[c];
  sheet.r(k, l)[c] = kept + step;
  sheet.energy.internal_force(sheet.r, up);
  sheet.r(k, l)[c] = kept - step;
  sheet.energy.internal_force(sheet.r, down);
  sheet.r(k, l)[c] = kept;
}

// The force at (k, l) by its definition, f_q = −Σ_p ∂E_p/∂r_q, with every gradient from
// node_energy at the nodes p of q's stencil that lie in the grid.
Vec3 force_from_node_gradients(const CosseratEnergy& energy, const Field<Vec3>& r,
                               const Block& b, int k, int l) {
  Vec3 force;
  for (int dl = -1; dl <= 1; ++dl)
    for (int dk = -1; dk <= 1; ++dk) {
      const int pk = k + dk, pl = l + dl;
      if (pk < 0 || pk >= b.m || pl < 0 || pl >= b.n) continue;
      CosseratEnergy::StencilGradient g;
      energy.node_energy(r, pk, pl, &g);
      force -= g[3 * (1 - dl) + (1 - dk)];
    }
  return force;
}

constexpr Quadrature kQuadratures[] = {Quadrature::trapezoidal, Quadrature::nodal};

const char* name(Quadrature q) { return q == Quadrature::trapezoidal ? "trapezoidal" : "nodal"; }

Scene coupled_sheet() {
  // Unequal spacings and a coupling φ, so every term of E is exercised.
  Scene s = testing::flat_sheet(7, 6);
  s.size2 = 8.0;
  s.material.xi = {0.3, 0.2, 0.4};
  s.material.phi = {0.05, 0.02, 0.03};
  return s;
}

// The threads' bands of rows follow their speeds (RowBalance), so the forces must not depend on
// where a band ends: on every split of the owned rows among three threads, the forces and
// normals are bitwise those of one thread, on the whole grid and on a block of it whose low rows
// are another rank's.
TEST(EnergyForm, ForcesAreBitwiseTheSameOnEverySplitOfTheRows) {
  const Scene scene = [] {
    Scene s = coupled_sheet();
    s.m = 19;  // rows longer than a lane block, with a remainder
    s.n = 9;
    return s;
  }();
  const RestState rest = flat_rest_state(scene.material, scene.u, scene.v);
  Block whole = Block::whole(scene.m, scene.n, MPI_COMM_SELF);
  Block part = whole;
  part.l0 = 2;
  const int threads_before = omp_get_max_threads();
  for (const Quadrature q : kQuadratures)
  for (const Block* block : {&whole, &part}) {
    SCOPED_TRACE(name(q));
    const Block& b = *block;
    Field<Vec3> r(b);
    fill_with_ghosts(b, r, [&](int k, int l) { return testing::deformed(scene, k, l); });
    Field<Vec3> force_one(b), normals_one(b);
    omp_set_num_threads(1);
    CosseratEnergy one(b, scene.h1(), scene.h2(), rest, q);
    one.internal_force(r, force_one, &normals_one);
    omp_set_num_threads(3);
    CosseratEnergy three(b, scene.h1(), scene.h2(), rest, q);
    const long rows = b.owned_l();
    int splits = 0;
    for (long first = 1; first < rows - 1; ++first)
      for (long second = first + 1; second < rows; ++second) {
        three.row_balance().assign({0, first, second, rows});
        Field<Vec3> force(b), normals(b);
        three.internal_force(r, force, &normals);
        ++splits;
        for (int l = b.l0; l < b.l1; ++l)
          for (int k = b.k0; k < b.k1; ++k)
            for (int c = 0; c < 3; ++c) {
              ASSERT_EQ(force(k, l)[c], force_one(k, l)[c])
                  << "bands from rows 0, " << first << ", " << second << "; node " << k
                  << ", " << l;
              ASSERT_EQ(normals(k, l)[c], normals_one(k, l)[c]);
            }
      }
    EXPECT_EQ(splits, (rows - 1) * (rows - 2) / 2);
  }
  omp_set_num_threads(threads_before);
}

// −∂E/∂r by central differences of E, against the kernel's force at every node and component.
TEST(EnergyForm, ForceIsMinusTheGradientOfTheEnergy) {
  for (const Quadrature q : kQuadratures) {
  SCOPED_TRACE(name(q));
  Sheet sheet(coupled_sheet(), q);
  Field<Vec3> force(sheet.block);
  sheet.energy.internal_force(sheet.r, force);
  const double step = 1e-6;
  double worst = 0.0, largest = 0.0;
  for (int l = 0; l < sheet.scene.n; ++l)
    for (int k = 0; k < sheet.scene.m; ++k)
      for (int c = 0; c < 3; ++c) {
        const double expected = minus_difference(sheet, k, l, c, step);
        worst = std::max(worst, std::abs(force(k, l)[c] - expected));
        largest = std::max(largest, std::abs(expected));
      }
  ASSERT_GT(largest, 1.0);  // the sheet is well away from rest
  EXPECT_LT(worst, 1e-6 * largest) << "largest force component " << largest;
  }
}

// The row kernel (interior nodes eight lanes at a time, the border ring through node_energy)
// against the definition: f_q = −Σ_p ∂E_p/∂r_q with every gradient from node_energy, on sheets
// whose rows are shorter than, equal to and longer than a lane block, for every combination of
// terms the kernel specialises (no curvature, no coupling, all), with and without normals, on
// the whole grid and on a block of it. Only the order of the sums differs, so the two agree to
// round-off.
TEST(EnergyForm, RowKernelAgreesWithTheNodeGradients) {
  struct Case {
    int m, n;
    Sym2 xi, phi;
  };
  const Case cases[] = {{3, 3, {0.3, 0.2, 0.4}, {0.05, 0.02, 0.03}},
                        {9, 5, {0.3, 0.2, 0.4}, {0.05, 0.02, 0.03}},
                        {10, 12, {0.3, 0.2, 0.4}, {0.0, 0.0, 0.0}},
                        {21, 7, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}},
                        {19, 17, {0.0, 0.0, 0.0}, {0.05, 0.0, 0.0}}};
  for (const Quadrature q : kQuadratures)
  for (const Case& c : cases) {
    SCOPED_TRACE(name(q));
    Scene scene = testing::flat_sheet(c.m, c.n);
    scene.size2 = 8.0;
    scene.material.xi = c.xi;
    scene.material.phi = c.phi;
    const RestState rest = flat_rest_state(scene.material, scene.u, scene.v);
    Block whole = Block::whole(c.m, c.n, MPI_COMM_SELF);
    // A block of the grid away from its borders on the low sides, reaching them on the high.
    Block part = whole;
    part.k0 = c.m / 3;
    part.l0 = c.n / 2;
    for (const Block* block : {&whole, &part}) {
      const Block& b = *block;
      Field<Vec3> r(b), force(b), normals(b);
      fill_with_ghosts(b, r, [&](int k, int l) { return testing::deformed(scene, k, l); });
      CosseratEnergy energy(b, scene.h1(), scene.h2(), rest, q);
      // A first call at rest positions: nothing of it may carry into the next.
      {
        Field<Vec3> rest_r(b);
        fill_with_ghosts(b, rest_r, [&](int k, int l) {
          return (k * scene.h1()) * scene.u + (l * scene.h2()) * scene.v;
        });
        energy.internal_force(rest_r, force);
      }
      for (const bool with_normals : {false, true}) {
        energy.internal_force(r, force, with_normals ? &normals : nullptr);
        double worst = 0.0, largest = 0.0, worst_normal = 0.0;
        for (int l = b.l0; l < b.l1; ++l)
          for (int k = b.k0; k < b.k1; ++k) {
            const Vec3 expected = force_from_node_gradients(energy, r, b, k, l);
            worst = std::max(worst, norm(force(k, l) - expected));
            largest = std::max(largest, norm(expected));
            if (with_normals) {
              Vec3 n;
              energy.node_energy(r, k, l, nullptr, &n);
              worst_normal = std::max(worst_normal, norm(normals(k, l) - n));
            }
          }
        ASSERT_GT(largest, 1.0);
        EXPECT_LT(worst, 1e-12 * largest)
            << c.m << " x " << c.n << " block from (" << b.k0 << ", " << b.l0 << ")";
        EXPECT_LT(worst_normal, 1e-14) << c.m << " x " << c.n;
      }
    }
  }
}

// A sheet squeezed along x¹ to between a twentieth and a half of its width, crinkled out of
// its plane from node to node and scrambled, so that many corner triangles and cells are
// crushed below a quarter of their rest area, some fold over, and the rest are not
// (docs/equations.md, "Crushed cells").
Vec3 crushed(const Scene& s, int k, int l) {
  const double h1 = s.h1(), h2 = s.h2();
  return {(0.05 + 0.1 * l) * k * h1 + 0.1 * h1 * std::sin(1.7 * k + 0.4 * l),
          0.15 * h1 * std::cos(1.3 * k - 0.9 * l) * ((k + l) % 2 == 0 ? 1.0 : -1.0),
          0.9 * l * h2 + 0.2 * h2 * std::sin(0.8 * k * l)};
}

// How many of the sheet's corner triangles |E × F| are below and above δ = ¼ h₁h₂ (u ⊥ v).
std::pair<int, int> crushed_corners(const Scene& s, const Field<Vec3>& r) {
  int below = 0, above = 0;
  for (int l = 0; l + 1 < s.n; ++l)
    for (int k = 0; k + 1 < s.m; ++k) {
      const double c = norm(cross(r(k + 1, l) - r(k, l), r(k, l + 1) - r(k, l)));
      (c < 0.25 * s.h1() * s.h2() ? below : above) += 1;
    }
  return {below, above};
}

// Where cells are crushed the normals leave c/|c| for a bounded blend; the force is still the
// exact negative gradient of the energy, by central differences, and the row kernel still
// agrees with the node gradients.
TEST(EnergyForm, ForceIsTheGradientWhereCellsAreCrushed) {
  for (const Quadrature q : kQuadratures) {
    SCOPED_TRACE(name(q));
    Sheet sheet(coupled_sheet(), q);
    for (int l = 0; l < sheet.scene.n; ++l)
      for (int k = 0; k < sheet.scene.m; ++k) sheet.r(k, l) = crushed(sheet.scene, k, l);
    const auto [below, above] = crushed_corners(sheet.scene, sheet.r);
    ASSERT_GE(below, 5);
    ASSERT_GE(above, 5);
    std::printf("[crushed] %s: %d corner triangles crushed, %d not\n", name(q), below, above);
    Field<Vec3> force(sheet.block);
    sheet.energy.internal_force(sheet.r, force);
    const double step = 1e-7;
    double worst = 0.0, largest = 0.0, worst_kernel = 0.0;
    for (int l = 0; l < sheet.scene.n; ++l)
      for (int k = 0; k < sheet.scene.m; ++k) {
        const Vec3 expected = force_from_node_gradients(sheet.energy, sheet.r, sheet.block, k, l);
        worst_kernel = std::max(worst_kernel, norm(force(k, l) - expected));
        for (int c = 0; c < 3; ++c) {
          const double difference = minus_difference(sheet, k, l, c, step);
          worst = std::max(worst, std::abs(force(k, l)[c] - difference));
          largest = std::max(largest, std::abs(difference));
        }
      }
    ASSERT_GT(largest, 1.0);
    EXPECT_LT(worst, 1e-6 * largest) << "largest force component " << largest;
    EXPECT_LT(worst_kernel, 1e-12 * largest);
  }
}

// A sheet folded flat across its middle row: rows below it lie in the plane y = 0, rows above it
// back over them `gap` higher, and the crease row between, every edge at its rest length. The
// crease's corner units cancel, so its normal's sum is crushed (docs/equations.md, "Creases
// folded flat").
Vec3 folded_flat(const Scene& s, int k, int l, double gap) {
  const double h1 = s.h1(), h2 = s.h2();
  const int crease = s.n / 2;
  if (l < crease) return {k * h1, 0.0, l * h2};
  if (l > crease) return {k * h1, gap, (2 * crease - l) * h2};
  return {k * h1, 0.5 * gap, (crease - 1) * h2 + std::sqrt(h2 * h2 - 0.25 * gap * gap)};
}

// Closing a crease folded flat further never releases bending energy: its curvature only
// grows. Its corner units cancel, so the sum they make is crushed, and before the lost bending
// was kept the bounded normal shrank with the gap and took the crease's bending energy with it:
// here 26.8 J at a gap of a fifth of the spacing, 6.2 J at a twentieth (checked), a pull that
// pressed the fold of the two-layer test of test_self_contact.cpp shut at 35 times gravity
// against self-contact. The force is the exact gradient of the energy there too.
TEST(EnergyForm, ClosingACreaseFoldedFlatReleasesNoEnergy) {
  for (const Quadrature q : kQuadratures) {
    SCOPED_TRACE(name(q));
    double wider = 0.0;
    for (const double gap : {0.2, 0.05, 0.01, 0.002}) {
      SCOPED_TRACE(::testing::Message() << "gap " << gap << " spacings");
      Scene scene = testing::flat_sheet(7, 9);
      scene.material.phi = {0.0, 0.0, 0.0};
      Sheet sheet(scene, q);
      for (int l = 0; l < scene.n; ++l)
        for (int k = 0; k < scene.m; ++k)
          sheet.r(k, l) = folded_flat(scene, k, l, gap * scene.h2());
      const double energy = sheet.total();
      std::printf("[crease] %s, gap %.3f spacings: %.6f J\n", name(q), gap, energy);
      EXPECT_GE(energy, wider);
      wider = energy;
      Field<Vec3> force(sheet.block);
      sheet.energy.internal_force(sheet.r, force);
      const int crease = scene.n / 2;
      double worst = 0.0, largest = 0.0;
      for (int l = crease - 2; l <= crease + 2; ++l)
        for (int k = 0; k < scene.m; ++k) {
          const Vec3 expected = force_from_node_gradients(sheet.energy, sheet.r, sheet.block, k, l);
          worst = std::max(worst, norm(force(k, l) - expected));
          for (int c = 0; c < 3; ++c) {
            const double difference = minus_difference(sheet, k, l, c, 1e-7);
            worst = std::max(worst, std::abs(force(k, l)[c] - difference));
            largest = std::max(largest, std::abs(difference));
          }
        }
      EXPECT_LT(worst, 1e-6 * largest) << "largest force component " << largest;
    }
  }
}

// A portable x86-64 build runs the interior rows through a copy of the kernel compiled for
// AVX2 where the CPU has it (docs/kernel.md, "The run-time wide kernel"); its forces and normals
// must be bitwise the portable copy's, so that a run gives the same bits on every x86-64 CPU:
// on sheets crushed and not (the kernel's bounded and unbounded paths), with and without
// bending and coupling, in both quadratures, with rows of several lane blocks and a remainder.
TEST(EnergyForm, TheWideKernelGivesThePortableKernelsBits) {
  if (!wide_copies_available())
    GTEST_SKIP() << "this build has no wide copy of the kernel, or this CPU no AVX2";
  for (const Quadrature q : kQuadratures)
  for (const bool bending : {true, false})
  for (const bool crush : {false, true}) {
    SCOPED_TRACE(::testing::Message() << name(q) << (bending ? ", bending" : ", no bending")
                                    << (crush ? ", crushed" : ", deformed"));
    Scene scene = coupled_sheet();
    scene.m = 29;
    scene.n = 9;
    if (!bending) scene.material.xi = scene.material.phi = {0.0, 0.0, 0.0};
    Sheet sheet(scene, q);
    if (crush) {
      for (int l = 0; l < scene.n; ++l)
        for (int k = 0; k < scene.m; ++k) sheet.r(k, l) = crushed(scene, k, l);
      ASSERT_GE(crushed_corners(scene, sheet.r).first, 5);
    }
    ASSERT_TRUE(sheet.energy.wide_kernel());
    Field<Vec3> wide(sheet.block), wide_normals(sheet.block);
    sheet.energy.internal_force(sheet.r, wide, &wide_normals);
    sheet.energy.set_wide_kernel(false);
    ASSERT_FALSE(sheet.energy.wide_kernel());
    Field<Vec3> portable(sheet.block), portable_normals(sheet.block);
    sheet.energy.internal_force(sheet.r, portable, &portable_normals);
    double largest = 0.0;
    for (int l = 0; l < scene.n; ++l)
      for (int k = 0; k < scene.m; ++k) {
        largest = std::max(largest, norm(portable(k, l)));
        for (int c = 0; c < 3; ++c) {
          ASSERT_EQ(wide(k, l)[c], portable(k, l)[c]) << "node " << k << ", " << l;
          ASSERT_EQ(wide_normals(k, l)[c], portable_normals(k, l)[c]) << "node " << k << ", " << l;
        }
      }
    ASSERT_GT(largest, 1.0);
  }
}

// The stiffness of a rest sheet whose node p = (3, 3) is moved to within d h of the line
// through its neighbours (4, 3) and (3, 4), so that p's corner triangle between them has |c| ~
// d h² while its neighbours stay where they were. With c/|c| that corner's unit normal turns at
// a rate 1/|c| under an out-of-plane move of p, so the bending stiffness grows as 1/d² and a
// step stable at d = 1e-2 would blow up at d = 1e-3; with the crushed-cell blend it stops
// growing once the corner is crushed. The stiffness is the largest diagonal entry of −∂f/∂r.
double collapsed_corner_stiffness(Quadrature q, double d) {
  Sheet sheet(coupled_sheet(), q);
  const Scene& s = sheet.scene;
  for (int l = 0; l < s.n; ++l)
    for (int k = 0; k < s.m; ++k) sheet.r(k, l) = (k * s.h1()) * s.u + (l * s.h2()) * s.v;
  const Vec3 across = sheet.r(3, 3) - 0.5 * (sheet.r(4, 3) + sheet.r(3, 4));
  sheet.r(3, 3) = 0.5 * (sheet.r(4, 3) + sheet.r(3, 4)) + (d * s.h1() / norm(across)) * across;
  Field<Vec3> up(sheet.block), down(sheet.block);
  const double step = 1e-4 * d * s.h1();
  double largest = 0.0;
  for (int l = 0; l < s.n; ++l)
    for (int k = 0; k < s.m; ++k)
      for (int c = 0; c < 3; ++c) {
        forces_either_side(sheet, k, l, c, step, up, down);
        largest = std::max(largest, -(up(k, l)[c] - down(k, l)[c]) / (2.0 * step));
      }
  return largest;
}

TEST(EnergyForm, StiffnessStaysBoundedAsACornerIsCrushed) {
  for (const Quadrature q : kQuadratures) {
    SCOPED_TRACE(name(q));
    const double coarse = collapsed_corner_stiffness(q, 1e-2);
    const double fine = collapsed_corner_stiffness(q, 1e-3);
    std::printf("[crushed] %s: largest stiffness %.3e N/m at d = 1e-2, %.3e at 1e-3\n", name(q),
                coarse, fine);
    ASSERT_GT(coarse, 0.0);
    EXPECT_LT(fine, 1.5 * coarse);
  }
}

// The Jacobian of the force is the negative Hessian of E: symmetric, to finite-difference noise.
TEST(EnergyForm, JacobianIsSymmetric) {
  for (const Quadrature q : kQuadratures) {
  SCOPED_TRACE(name(q));
  Sheet sheet(coupled_sheet(), q);
  const int m = sheet.scene.m, n = sheet.scene.n, size = 3 * m * n;
  std::vector<double> J(static_cast<std::size_t>(size) * size);
  Field<Vec3> up(sheet.block), down(sheet.block);
  const double step = 1e-6;
  double largest = 0.0;
  for (int column = 0; column < size; ++column) {
    const int node = column / 3, c = column % 3, k = node % m, l = node / m;
    forces_either_side(sheet, k, l, c, step, up, down);
    for (int row = 0; row < size; ++row) {
      const int rn = row / 3, rc = row % 3;
      const double d = (up(rn % m, rn / m)[rc] - down(rn % m, rn / m)[rc]) / (2.0 * step);
      J[static_cast<std::size_t>(row) * size + column] = d;
      largest = std::max(largest, std::abs(d));
    }
  }
  double worst = 0.0;
  for (int row = 0; row < size; ++row)
    for (int column = 0; column < row; ++column)
      worst = std::max(worst, std::abs(J[static_cast<std::size_t>(row) * size + column] -
                                        J[static_cast<std::size_t>(column) * size + row]));
  EXPECT_LT(worst, 1e-6 * largest) << "largest entry " << largest;
  }
}

// node_hessian, summed over the nodes, is the Hessian of E: exactly symmetric, and the derivative
// of −force by central differences to their truncation error, on the deformed sheet with every
// term and on the same sheet with a corner crushed to a hundredth of a spacing (the blend of
// docs/equations.md, "Crushed cells"); also without the coupling φ and without bending, which
// take their own interior code. A sign or a slot wrong in the differentiation shows as an O(1)
// relative difference.
TEST(EnergyForm, NodeHessiansAreTheDerivativeOfTheForce) {
  const auto uncoupled = [] {
    Scene s = coupled_sheet();
    s.material.phi = {0.0, 0.0, 0.0};
    return s;
  }();
  const auto unbent = [&] {
    Scene s = uncoupled;
    s.material.xi = {0.0, 0.0, 0.0};
    return s;
  }();
  struct Case {
    const char* name;
    Scene scene;
    bool crush;
  };
  for (const Case& c : {Case{"deformed", coupled_sheet(), false},
                        Case{"crushed", coupled_sheet(), true}, Case{"no phi", uncoupled, false},
                        Case{"no xi, phi", unbent, false}}) {
    SCOPED_TRACE(c.name);
    const bool crush = c.crush;
    Sheet sheet(c.scene);
    const Scene& s = sheet.scene;
    if (crush) {
      const Vec3 mid = 0.5 * (sheet.r(4, 3) + sheet.r(3, 4)), across = sheet.r(3, 3) - mid;
      sheet.r(3, 3) = mid + (1e-2 * s.h1() / norm(across)) * across;
    }
    const int m = s.m, n = s.n, size = 3 * m * n;
    std::vector<double> H(static_cast<std::size_t>(size) * size, 0.0);
    NodeHessian h;
    for (int l = 0; l < n; ++l)
      for (int k = 0; k < m; ++k) {
        sheet.energy.node_hessian(sheet.r, k, l, h);
        for (int a = 0; a < 9; ++a)
          for (int b = 0; b < 9; ++b) {
            const int ak = k + a % 3 - 1, al = l + a / 3 - 1, bk = k + b % 3 - 1, bl = l + b / 3 - 1;
            if (ak < 0 || ak >= m || al < 0 || al >= n || bk < 0 || bk >= m || bl < 0 || bl >= n)
              continue;
            for (int i = 0; i < 3; ++i)
              for (int j = 0; j < 3; ++j)
                H[static_cast<std::size_t>(3 * (al * m + ak) + i) * size + 3 * (bl * m + bk) + j] +=
                    h.entries[static_cast<std::size_t>((3 * a + i) * 27 + 3 * b + j)];
          }
      }
    Field<Vec3> up(sheet.block), down(sheet.block);
    const double step = crush ? 1e-7 : 1e-6;
    double largest = 0.0, worst = 0.0, asymmetry = 0.0;
    for (int column = 0; column < size; ++column) {
      const int node = column / 3, c = column % 3;
      forces_either_side(sheet, node % m, node / m, c, step, up, down);
      for (int row = 0; row < size; ++row) {
        const int rn = row / 3, rc = row % 3;
        const double difference =
            -(up(rn % m, rn / m)[rc] - down(rn % m, rn / m)[rc]) / (2.0 * step);
        const double exact = H[static_cast<std::size_t>(row) * size + column];
        largest = std::max(largest, std::abs(exact));
        worst = std::max(worst, std::abs(exact - difference));
        asymmetry =
            std::max(asymmetry, std::abs(exact - H[static_cast<std::size_t>(column) * size + row]));
      }
    }
    std::printf("[hessian] %s: largest entry %.3e, off the differences by %.2e, asymmetry %.2e\n",
                c.name, largest, worst, asymmetry);
    ASSERT_GT(largest, 1.0);
    EXPECT_LT(worst, 1e-6 * largest);
    EXPECT_LT(asymmetry, 1e-13 * largest);
  }
}

// docs/equations.md §5 item 1 for the energy form: a rotated and translated rest sheet stores no
// energy and feels no force.
TEST(EnergyForm, RigidMotionHasNoEnergyAndNoForce) {
  for (const Quadrature q : kQuadratures) {
  SCOPED_TRACE(name(q));
  Sheet sheet(coupled_sheet(), q);
  const double c = std::cos(0.7), s = std::sin(0.7);
  for (int l = 0; l < sheet.scene.n; ++l)
    for (int k = 0; k < sheet.scene.m; ++k) {
      const double x = k * sheet.scene.h1(), z = l * sheet.scene.h2();
      // A shear-free rotation needs orthonormal tangents: rotate in a plane, then tilt it.
      const Vec3 in_plane{c * x - s * z, 0.0, s * x + c * z};
      const double t = 0.4;
      sheet.r(k, l) = Vec3{in_plane.x, std::sin(t) * in_plane.z, std::cos(t) * in_plane.z} +
                      Vec3{3.0, -1.0, 0.5};
    }
  Field<Vec3> force(sheet.block);
  sheet.energy.internal_force(sheet.r, force);
  double worst = 0.0;
  for (int l = 0; l < sheet.scene.n; ++l)
    for (int k = 0; k < sheet.scene.m; ++k) worst = std::max(worst, norm(force(k, l)));
  // Against the force of a 1 % stretch, the scale of what a real deformation gives.
  const double zeta = sheet.scene.material.zeta[0];
  EXPECT_LT(worst, 1e-12 * zeta * sheet.scene.h2());
  EXPECT_LT(std::abs(sheet.total()), 1e-20 * zeta * sheet.scene.size1 * sheet.scene.size2);
  }
}

// E depends on the positions only through their differences and is unchanged by a rotation, so
// the internal forces of any deformed sheet carry no net force and no net torque: momentum and
// angular momentum are conserved. The sheet is wider than two lane blocks, so interior nodes
// (whose own slot is minus the other five) and the border ring both take part.
TEST(EnergyForm, InternalForcesHaveNoNetForceAndNoNetTorque) {
  Scene scene = coupled_sheet();
  scene.m = 21;
  scene.n = 9;
  for (const Quadrature q : kQuadratures) {
  SCOPED_TRACE(name(q));
  Sheet sheet(scene, q);
  Field<Vec3> force(sheet.block);
  sheet.energy.internal_force(sheet.r, force);
  Vec3 net, torque;
  double magnitude = 0.0, lever = 0.0;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) {
      net += force(k, l);
      torque += cross(sheet.r(k, l), force(k, l));
      magnitude += norm(force(k, l));
      lever = std::max(lever, norm(sheet.r(k, l)));
    }
  ASSERT_GT(magnitude, 1.0);  // the sheet is well away from rest
  EXPECT_LT(norm(net), 1e-13 * magnitude);
  EXPECT_LT(norm(torque), 1e-13 * magnitude * lever);
  }
}

// Kinetic + elastic + gravitational energy of a damped sheet falling from a held corner, after
// every step: the largest rise from one step to the next, and what damping took in all.
double largest_energy_rise(Discretisation d, double dt, double* total_drop) {
  Scene scene = testing::flat_sheet(10, 10);
  scene.discretisation = d;
  scene.integrator = Integrator::velocity_verlet;
  scene.gravity = {0.0, -9.8, 0.0};
  scene.damping = 0.2;
  scene.fixes.push_back(testing::fix_nodes({{0, 9}}));
  scene.u = {1.0, 0.0, 0.0};
  scene.v = {0.0, -1.0, 0.0};
  scene.dt = dt;
  Simulation sim(scene, MPI_COMM_SELF, any_scheme);
  auto total = [&] {
    const Diagnostics d = sim.diagnostics();
    return d.kinetic_energy + d.gravitational_energy + sim.elastic_energy();
  };
  const double first = total();
  double previous = first, rise = 0.0;
  const long steps = std::lround(1.0 / dt);
  for (long s = 0; s < steps; ++s) {
    EXPECT_FALSE(sim.step().has_value());
    const double now = total();
    rise = std::max(rise, now - previous);
    previous = now;
  }
  *total_drop = first - previous;
  return rise;
}

// The integrator may let the total wobble by its O(Δt²) error; measured, the total falls at
// every step at both steps here (largest rise 0), so the bound is round-off of the total.
TEST(EnergyForm, DampedRunNeverGainsEnergy) {
  for (const Discretisation d : {Discretisation::energy, Discretisation::energy_nodal})
    for (const double dt : {2e-3, 1e-3}) {
      double drop = 0.0;
      const double rise = largest_energy_rise(d, dt, &drop);
      EXPECT_GT(drop, 10.0) << "dt " << dt;  // the sheet falls: hundreds of joules damped
      EXPECT_LE(rise, 1e-12 * drop) << discretisation_name(d) << ", dt " << dt;
    }
}

// The material constants in physical terms (docs/materials.md, "Units"), from the energy of
// the grid itself on a flat rest sheet with u ⊥ v: a stretch e along x¹ stores 3ζ₁₁e² per unit
// area (tension 6ζ₁₁e), a shear angle γ stores ζ₁₂γ²/2 (shear force ζ₁₂γ), a bend of curvature
// κ stores 3ξ₁₁κ² (moment 6ξ₁₁κ, bending rigidity B = 6ξ₁₁). So ζ is in N/m, ξ in N m.
TEST(EnergyForm, MaterialConstants) {
  Scene s = testing::flat_sheet(51, 11);
  s.size1 = 0.5;
  s.size2 = 0.1;
  s.material.zeta = {300.0, 7.0, 300.0};
  s.material.xi = {2e-6, 2e-6, 2e-6};
  s.material.phi = {0.0, 0.0, 0.0};
  const double h1 = s.h1(), h2 = s.h2();
  for (const Quadrature q : kQuadratures) {
    SCOPED_TRACE(name(q));
    Sheet sheet(s, q);
    // The area each kind of term is summed over. Trapezoidal: the sheet's, L₁L₂, for every
    // term but κ₁₁, which lives at the nodes with both k-neighbours, (m − 2)h₁ L₂. Nodal: every
    // node carries one cell, h₁h₂, and the terms a node lacks a neighbour or its forward cell
    // for are left out.
    const bool trapezoidal = q == Quadrature::trapezoidal;
    const double sheet_area = (s.m - 1) * h1 * (s.n - 1) * h2, cell = h1 * h2;
    const double stretch_area = trapezoidal ? sheet_area : s.m * s.n * cell;
    const double shear_area = trapezoidal ? sheet_area : (s.m - 1) * (s.n - 1) * cell;
    const double bend_area = trapezoidal ? (s.m - 2) * h1 * (s.n - 1) * h2 : (s.m - 2) * s.n * cell;
    const auto place = [&](auto&& position) {
      for (int l = 0; l < s.n; ++l)
        for (int k = 0; k < s.m; ++k) sheet.r(k, l) = position(k * h1, l * h2);
    };

    const double stretch = 1.001;  // ε₁₁ = ½(λ² − 1), exactly on every edge
    place([&](double x, double z) { return Vec3{stretch * x, 0.0, z}; });
    const double epsilon = 0.5 * (stretch * stretch - 1.0);
    EXPECT_NEAR(sheet.total() / stretch_area, 3.0 * s.material.zeta[0] * epsilon * epsilon,
                1e-12);

    const double gamma = 1e-3;  // a1 · a2 = γ, a_αα = 1 + γ²/4: ε₁₂ = γ/2, ε_αα = γ²/8
    place(
        [&](double x, double z) { return Vec3{x + 0.5 * gamma * z, 0.0, z + 0.5 * gamma * x}; });
    const double shear = s.material.zeta[1] * gamma * gamma / 2.0;
    const double stretched = 2.0 * 3.0 * s.material.zeta[0] * std::pow(gamma * gamma / 8.0, 2);
    EXPECT_NEAR(sheet.total(), shear_area * shear + stretch_area * stretched,
                1e-9 * sheet.total());

    // A cylinder of radius R about z, the nodes on the circle: D₁₁r is radial, of length
    // κ = 2(1 − cos(h/R))R/h² (→ 1/R), and every k-edge is a chord, shorter than h, which adds
    // a uniform ε₁₁ = ½((2R sin(h/2R)/h)² − 1).
    const double R = 1.0;
    place([&](double x, double z) {
      return Vec3{R * std::sin(x / R), R * (1.0 - std::cos(x / R)), z};
    });
    const double kappa = 2.0 * (1.0 - std::cos(h1 / R)) * R / (h1 * h1);
    const double chord = 2.0 * R * std::sin(h1 / (2.0 * R)) / h1;
    const double shortened = 0.5 * (chord * chord - 1.0);
    const double bending = 3.0 * s.material.xi[0] * kappa * kappa;
    EXPECT_NEAR(sheet.total(),
                stretch_area * 3.0 * s.material.zeta[0] * shortened * shortened +
                    bend_area * bending,
                1e-9 * sheet.total());
    EXPECT_NEAR(kappa, 1.0 / R, 1e-5);
  }
}

}  // namespace
}  // namespace cosserat
