// The semi-implicit baseline on PETSc: a DMDA over the solver's own
// decomposition, the Jacobian of the internal acceleration assembled from the model's exact
// node Hessians (or by MatFDColoring for a model without them), KSP for the step's linear
// system (docs/semi-implicit.md).

#include <fmt/format.h>
#include <petscdmda.h>
#include <petscksp.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <optional>
#include <source_location>
#include <stdexcept>
#include <string>

#include "cosserat/baseline/semi_implicit.hpp"
#include "semi_implicit_solver.hpp"

namespace cosserat {

namespace {

void check(PetscErrorCode code, std::source_location where = std::source_location::current()) {
  if (code != 0) {
    throw std::runtime_error(fmt::format("PETSc error {} in {} ({}:{})", static_cast<int>(code),
                                         where.function_name(), where.file_name(), where.line()));
  }
}

bool petsc_started_here = false;

void start_petsc() {
  PetscBool initialized = PETSC_FALSE;
  check(PetscInitialized(&initialized));
  if (initialized) return;
  // Signals stay the driver's: a job's SIGTERM or a crash ends the run as it
  // does without PETSc.
  check(PetscOptionsSetValue(nullptr, "-no_signal_handler", nullptr));
  check(PetscInitializeNoArguments());
  petsc_started_here = true;
}

// Runs a PETSc call whose failure means bad input (a name PETSc does not know),
// quietly, and reports it as a scene error naming `key`.
template <class Call>
void set_or_refuse(Call&& call, const std::string& what) {
  check(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr));
  const PetscErrorCode code = call();
  check(PetscPopErrorHandler());
  if (code != 0) throw SceneError(what);
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

struct SemiImplicitSolver::Impl {
  Impl(const Scene& scene, const Decomposition& decomposition, const Block& block,
       Dynamics& dynamics);
  ~Impl();

  // The function MatFDColoring differences: the internal acceleration at the
  // global vector x.
  static PetscErrorCode internal_acceleration(void* unused, Vec x, Vec f, void* self);

  // Offset of component c of owned node (k, l) in this rank's part of a global
  // vector.
  PetscInt offset(int k, int l, int c) const {
    return (static_cast<PetscInt>(l - block->l0) * block->owned_k() + (k - block->k0)) * 3 + c;
  }
  void set_up_colouring(const Scene& scene);
  void copy_in(const Field<Vec3>& field, Vec v) const;
  void copy_out(Vec v, Field<Vec3>& field) const;
  // The factor each row of the system is multiplied by: the node's mass over the interior
  // mass with the exact Jacobian, 1 with a differenced one.
  double row_weight(int k, int l) const {
    return exact ? dynamics->model().node_mass().weight(k, l) : 1.0;
  }
  // −Σ_p ∂²E_p/∂r∂r over the interior mass into the owned rows of `jacobian`.
  void assemble_hessians(const Field<Vec3>& r);
  // A node's row couples it to the 5 × 5 nodes around it at most (E_p reads its 3 × 3 box).
  static constexpr int kCouplings = 25;
  // assemble_hessians' rows of nodes not yet in the matrix, three, row q at q mod 3: for each
  // owned node of a row its 3 × 3 blocks, and the couplings that have one (a bit each).
  std::vector<double> rows_ahead;
  std::vector<std::uint32_t> coupled;
  std::vector<NodeHessian> row_hessians;  // one row of nodes' Hessians, the block's and its ring's
  // Where the values go once the pattern is fixed (locate_blocks): for each owned node, each
  // coupling and each of its three rows, the place of the block's three values in the value
  // array of the diagonal part (from 0) or of the off-diagonal part (−1 for its first, −2 ...).
  void locate_blocks();
  std::vector<std::uint32_t> coupled_pattern;  // each owned node's couplings, from the first J
  std::vector<std::int64_t> block_offsets;      // empty: MatSetValuesBlockedStencil
  bool located = false;
  Mat diagonal_part = nullptr, off_diagonal_part = nullptr;

  const Block* block;
  Dynamics* dynamics;
  double dt;
  // The exact Jacobian from node Hessians: the system is then solved times the node weights
  // w (masses over the interior mass), which makes it symmetric (docs/semi-implicit.md).
  bool exact;
  bool second_order;  // semi-implicit-2: ½ J, and −½ J d on the right-hand side
  DM da = nullptr;
  Mat jacobian = nullptr;  // W J, kept across the steps that reuse it
  Mat system = nullptr;    // the step's matrix, built from it each step
  long jacobian_every;     // rebuild J on the steps that are multiples of it
  bool built = false;      // J exists
  bool fresh = false;      // J was rebuilt for this step
  MatFDColoring colouring = nullptr;
  KSP ksp = nullptr;
  Vec x = nullptr, local = nullptr, b = nullptr, delta = nullptr;
  Vec weights = nullptr, shift = nullptr;  // w at each unknown; the diagonal's share, c w
  PetscInt first_row = 0;
  Field<Vec3> r_view, a_view;
  LinearSolveStats stats;
};

SemiImplicitSolver::Impl::Impl(const Scene& scene, const Decomposition& decomposition,
                               const Block& block_, Dynamics& dynamics_)
    : block(&block_),
      dynamics(&dynamics_),
      dt(scene.dt),
      exact(dynamics_.model().has_node_hessian()),
      second_order(scene.integrator == Integrator::semi_implicit_2),
      jacobian_every(scene.solver.jacobian_every),
      r_view(block_),
      a_view(block_) {
  start_petsc();
  const Block& bl = *block;
  std::vector<PetscInt> widths_k, widths_l;
  for (const int w : decomposition.widths_k()) widths_k.push_back(w);
  for (const int w : decomposition.widths_l()) widths_l.push_back(w);
  // Same ranks, same blocks: a DMDA numbers its processes k-fastest, as
  // Decomposition does. Its ghost ring is the force kernel's (kGhostWidth, box:
  // diagonals included).
  check(DMDACreate2d(bl.comm, DM_BOUNDARY_NONE, DM_BOUNDARY_NONE, DMDA_STENCIL_BOX, bl.m, bl.n,
                     decomposition.parts_k(), decomposition.parts_l(), 3, kGhostWidth,
                     widths_k.data(), widths_l.data(), &da));
  check(DMSetUp(da));
  PetscInt xs, ys, xm, ym;
  check(DMDAGetCorners(da, &xs, &ys, nullptr, &xm, &ym, nullptr));
  if (xs != bl.k0 || ys != bl.l0 || xs + xm != bl.k1 || ys + ym != bl.l1) {
    throw std::logic_error("the DMDA's blocks differ from the solver's decomposition");
  }

  check(DMSetMatType(da, MATAIJ));
  check(DMCreateMatrix(da, &jacobian));
  check(MatDuplicate(jacobian, MAT_DO_NOT_COPY_VALUES, &system));
  // Its held rows and columns are zeroed each step; its pattern must stay J's for the next
  // step's copy.
  check(MatSetOption(system, MAT_KEEP_NONZERO_PATTERN, PETSC_TRUE));
  check(DMCreateGlobalVector(da, &x));
  check(VecDuplicate(x, &b));
  check(VecDuplicate(x, &delta));
  check(DMCreateLocalVector(da, &local));
  check(VecGetOwnershipRange(x, &first_row, nullptr));
  check(VecDuplicate(x, &weights));
  check(VecDuplicate(x, &shift));
  {
    Field<Vec3> w(bl);
    for (int l = bl.l0; l < bl.l1; ++l)
      for (int k = bl.k0; k < bl.k1; ++k) {
        const double weight = row_weight(k, l);
        w(k, l) = Vec3{weight, weight, weight};
      }
    copy_in(w, weights);
  }
  if (!exact) set_up_colouring(scene);

  check(KSPCreate(bl.comm, &ksp));
  check(KSPSetOperators(ksp, system, system));
  LinearSolver linear = scene.solver;
  PetscBool hypre = PETSC_FALSE;
  check(PetscHasExternalPackage("hypre", &hypre));
  const KrylovChoice choice =
      default_linear_solver(exact, static_cast<long>(bl.m) * bl.n, hypre == PETSC_TRUE);
  if (linear.ksp.empty()) linear.ksp = choice.ksp;
  if (linear.pc.empty()) linear.pc = choice.pc;
  set_or_refuse([&] { return KSPSetType(ksp, linear.ksp.c_str()); },
                fmt::format("{}: time.solver.ksp: PETSc has no Krylov method \"{}\" (for example "
                            "gmres, fgmres, bcgs, cg, richardson)",
                            scene.path, linear.ksp));
  PC pc;
  check(KSPGetPC(ksp, &pc));
  set_or_refuse([&] { return PCSetType(pc, linear.pc.c_str()); },
                fmt::format("{}: time.solver.pc: PETSc has no preconditioner \"{}\" (for example "
                            "bjacobi, jacobi, sor, gamg, none)",
                            scene.path, linear.pc));
  check(KSPSetTolerances(ksp, linear.rtol, linear.atol, PETSC_DEFAULT,
                         static_cast<PetscInt>(linear.max_iterations)));
  // The last step's δ starts the iteration (the stepper passes d = rⁿ − rⁿ⁻¹).
  check(KSPSetInitialGuessNonzero(ksp, PETSC_TRUE));
  set_or_refuse([&] { return KSPSetFromOptions(ksp); },
                "the PETSc options (--petsc or PETSC_OPTIONS) name a Krylov method or "
                "preconditioner PETSc does not have; see the message above");
}

// The finite-difference Jacobian, for a model without node Hessians: PETSc differences the
// internal acceleration over a colouring of the DMDA's box stencil.
void SemiImplicitSolver::Impl::set_up_colouring(const Scene& scene) {
  ISColoring colours;
  check(DMCreateColoring(da, IS_COLORING_GLOBAL, &colours));
  check(MatFDColoringCreate(jacobian, colours, &colouring));
  // PETSc takes the function type-erased; void(*)(void) is the cast GCC accepts
  // as generic.
  check(
      MatFDColoringSetFunction(colouring,
                               reinterpret_cast<PetscErrorCode (*)(void)>(
                                   reinterpret_cast<void (*)(void)>(&Impl::internal_acceleration)),
                               this));
  // A position's perturbation is sqrt(eps) times its size, but at least
  // sqrt(eps) times a grid spacing: PETSc's floor (1e-6) would perturb a node
  // near the origin by 1e-14 m and lose the difference in round-off.
  check(MatFDColoringSetParameters(colouring, PETSC_DEFAULT, std::min(scene.h1(), scene.h2())));
  check(MatFDColoringSetFromOptions(colouring));
  check(MatFDColoringSetUp(jacobian, colours, colouring));
  check(ISColoringDestroy(&colours));
}

SemiImplicitSolver::Impl::~Impl() {
  // Destruction must not throw; PETSc reports its own errors.
  KSPDestroy(&ksp);
  MatFDColoringDestroy(&colouring);
  MatDestroy(&system);
  MatDestroy(&jacobian);
  VecDestroy(&shift);
  VecDestroy(&weights);
  VecDestroy(&delta);
  VecDestroy(&b);
  VecDestroy(&local);
  VecDestroy(&x);
  DMDestroy(&da);
}

void SemiImplicitSolver::Impl::copy_in(const Field<Vec3>& field, Vec v) const {
  PetscScalar* data;
  check(VecGetArray(v, &data));
  const Block& bl = *block;
#pragma omp parallel for schedule(static)
  for (int l = bl.l0; l < bl.l1; ++l)
    for (int k = bl.k0; k < bl.k1; ++k)
      for (int c = 0; c < 3; ++c) data[offset(k, l, c)] = field(k, l)[c];
  check(VecRestoreArray(v, &data));
}

void SemiImplicitSolver::Impl::copy_out(Vec v, Field<Vec3>& field) const {
  const PetscScalar* data;
  check(VecGetArrayRead(v, &data));
  const Block& bl = *block;
#pragma omp parallel for schedule(static)
  for (int l = bl.l0; l < bl.l1; ++l)
    for (int k = bl.k0; k < bl.k1; ++k)
      field(k, l) = Vec3{data[offset(k, l, 0)], data[offset(k, l, 1)], data[offset(k, l, 2)]};
  check(VecRestoreArrayRead(v, &data));
}

PetscErrorCode SemiImplicitSolver::Impl::internal_acceleration(void*, Vec x, Vec f, void* self) {
  PetscFunctionBeginUser;
  Impl& s = *static_cast<Impl*>(self);
  PetscCall(DMGlobalToLocalBegin(s.da, x, INSERT_VALUES, s.local));
  PetscCall(DMGlobalToLocalEnd(s.da, x, INSERT_VALUES, s.local));
  PetscInt gxs, gys, gxm, gym;
  PetscCall(DMDAGetGhostCorners(s.da, &gxs, &gys, nullptr, &gxm, &gym, nullptr));
  PetscScalar*** in;
  PetscCall(DMDAVecGetArrayDOFRead(s.da, s.local, &in));
  for (PetscInt l = gys; l < gys + gym; ++l)
    for (PetscInt k = gxs; k < gxs + gxm; ++k)
      s.r_view(static_cast<int>(k), static_cast<int>(l)) =
          Vec3{in[l][k][0], in[l][k][1], in[l][k][2]};
  PetscCall(DMDAVecRestoreArrayDOFRead(s.da, s.local, &in));
  s.dynamics->internal_acceleration(s.r_view, s.a_view);
  PetscScalar* out;
  PetscCall(VecGetArray(f, &out));
  const Block& bl = *s.block;
  for (int l = bl.l0; l < bl.l1; ++l)
    for (int k = bl.k0; k < bl.k1; ++k)
      for (int c = 0; c < 3; ++c) out[s.offset(k, l, c)] = s.a_view(k, l)[c];
  PetscCall(VecRestoreArray(f, &out));
  PetscFunctionReturn(0);
}

SemiImplicitSolver::SemiImplicitSolver(const Scene& scene, const Decomposition& decomposition,
                                       const Block& block, Dynamics& dynamics)
    : impl_(std::make_unique<Impl>(scene, decomposition, block, dynamics)) {}

SemiImplicitSolver::~SemiImplicitSolver() = default;

// Each node p's Hessian adds into the rows of the owned nodes of its box, so a block takes the
// p of its owned nodes and of the ring around them (their E_p read two nodes out: the ghosts),
// over the slots each E_p reads. The p are taken row by row, and an owned row of nodes, whole
// once the p of the row above it are in, goes into the matrix then, each node's row at once
// (locate_blocks): inserted block by block as each p came, the insertion cost as much as the
// Hessians (5.6 µs a node on 120², docs/semi-implicit.md). Every entry sums its p from zero in
// the order of the p, row by row, on any decomposition and any threads: the matrix has the
// same bits.
void SemiImplicitSolver::Impl::assemble_hessians(const Field<Vec3>& r) {
  const Block& bl = *block;
  const ForceModel& model = dynamics->model();
  const double scale = -1.0 / model.node_mass().interior;
  const std::size_t width = static_cast<std::size_t>(bl.owned_k());
  // Zero from the first Jacobian on: each row is cleared as it goes into the matrix.
  rows_ahead.resize(3 * width * kCouplings * 9, 0.0);
  coupled.resize(3 * width, 0u);
  coupled_pattern.resize(width * static_cast<std::size_t>(bl.owned_l()));
  PetscScalar* diagonal_values = nullptr;
  PetscScalar* off_diagonal_values = nullptr;
  if (!block_offsets.empty()) {
    check(MatSeqAIJGetArray(diagonal_part, &diagonal_values));
    if (off_diagonal_part != nullptr)
      check(MatSeqAIJGetArray(off_diagonal_part, &off_diagonal_values));
  }
  // Row q of nodes into the matrix: each owned node's row, over the neighbours it couples to.
  const auto flush = [&](int q) {
    const std::size_t ring = static_cast<std::size_t>(q % 3) * width;
    for (int k = bl.k0; k < bl.k1; ++k) {
      const std::size_t node = ring + static_cast<std::size_t>(k - bl.k0);
      const std::size_t owned =
          static_cast<std::size_t>(q - bl.l0) * width + static_cast<std::size_t>(k - bl.k0);
      if (diagonal_values != nullptr) {
        const std::int64_t* offsets = &block_offsets[owned * kCouplings * 3];
        for (int c = 0; c < kCouplings; ++c) {
          if (!(coupled[node] & (1u << c))) continue;
          const double* block_values = &rows_ahead[(node * kCouplings + c) * 9];
          for (int i = 0; i < 3; ++i) {
            const std::int64_t at = offsets[3 * c + i];
            PetscScalar* out = at >= 0 ? diagonal_values + at : off_diagonal_values + (-at - 1);
            std::copy_n(block_values + 3 * i, 3, out);
          }
        }
      } else {
        const MatStencil row{0, q, k, 0};
        MatStencil columns[kCouplings];
        PetscScalar values[9 * kCouplings];
        int count = 0;
        for (int c = 0; c < kCouplings; ++c)
          if (coupled[node] & (1u << c)) columns[count++] = {0, q + c / 5 - 2, k + c % 5 - 2, 0};
        int v = 0;
        for (int i = 0; i < 3; ++i)
          for (int c = 0; c < kCouplings; ++c)
            if (coupled[node] & (1u << c))
              for (int j = 0; j < 3; ++j)
                values[v++] = rows_ahead[(node * kCouplings + c) * 9 + 3 * i + j];
        check(
            MatSetValuesBlockedStencil(jacobian, 1, &row, count, columns, values, INSERT_VALUES));
        coupled_pattern[owned] = coupled[node];
      }
      std::fill_n(&rows_ahead[node * kCouplings * 9], kCouplings * 9, 0.0);
      coupled[node] = 0u;
    }
  };
  int next = bl.l0;  // the next owned row to go in
  const int ka = std::max(bl.k0 - 1, 0), kb = std::min(bl.k1 + 1, bl.m);
  row_hessians.resize(static_cast<std::size_t>(kb - ka));
  for (int l = std::max(bl.l0 - 1, 0); l < std::min(bl.l1 + 1, bl.n); ++l) {
    // The row's Hessians on the threads, each a function of its box alone; summed in order
    // below, so the bits do not depend on the threads.
#pragma omp parallel for schedule(static)
    for (int k = ka; k < kb; ++k) model.node_hessian(r, k, l, row_hessians[k - ka]);
    for (int k = ka; k < kb; ++k) {
      const NodeHessian& h = row_hessians[static_cast<std::size_t>(k - ka)];
      for (int ri = 0; ri < h.count; ++ri) {
        const int a = h.read[ri], qk = k + a % 3 - 1, ql = l + a / 3 - 1;
        if (!bl.owns(qk, ql)) continue;
        const std::size_t node =
            static_cast<std::size_t>(ql % 3) * width + static_cast<std::size_t>(qk - bl.k0);
        for (int ci = 0; ci < h.count; ++ci) {
          const int b = h.read[ci];
          // The column's place among the 5 × 5 nodes around the row's.
          const int c = (b / 3 - a / 3 + 2) * 5 + (b % 3 - a % 3 + 2);
          coupled[node] |= 1u << c;
          double* block_values =
              &rows_ahead[(node * kCouplings + static_cast<std::size_t>(c)) * 9];
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
              block_values[3 * i + j] +=
                  scale * h.entries[static_cast<std::size_t>((3 * a + i) * 27 + 3 * b + j)];
        }
      }
    }
    for (; next < std::min(l, bl.l1); ++next) flush(next);
  }
  for (; next < bl.l1; ++next) flush(next);
  if (diagonal_values != nullptr) {
    check(MatSeqAIJRestoreArray(diagonal_part, &diagonal_values));
    if (off_diagonal_part != nullptr)
      check(MatSeqAIJRestoreArray(off_diagonal_part, &off_diagonal_values));
  }
  // Also after the direct writes: the assembly marks the matrix changed (its state) for what
  // reads it.
  check(MatAssemblyBegin(jacobian, MAT_FINAL_ASSEMBLY));
  check(MatAssemblyEnd(jacobian, MAT_FINAL_ASSEMBLY));
  if (!located) locate_blocks();
}

// After the first assembly the pattern is fixed: each owned node's row of each block it couples
// to (coupled_pattern) is three consecutive values of a row of the diagonal part (columns of
// owned nodes) or of the off-diagonal part (the others), both sequential AIJ matrices whose
// columns are sorted. Writing there costs 0.5 µs a node where MatSetValuesBlockedStencil cost
// 2.4 (120², one thread, docs/semi-implicit.md). A matrix of another type, or a block not found
// where it should be, keeps MatSetValuesBlockedStencil.
void SemiImplicitSolver::Impl::locate_blocks() {
  const Block& bl = *block;
  located = true;
  PetscBool sequential = PETSC_FALSE, distributed = PETSC_FALSE;
  check(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(jacobian), MATSEQAIJ, &sequential));
  check(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(jacobian), MATMPIAIJ, &distributed));
  const PetscInt* columns_off = nullptr;  // the off-diagonal part's global columns, ascending
  if (sequential) {
    diagonal_part = jacobian;
    off_diagonal_part = nullptr;
  } else if (distributed) {
    check(MatMPIAIJGetSeqAIJ(jacobian, &diagonal_part, &off_diagonal_part, &columns_off));
  } else {
    return;
  }
  PetscInt first_column, end_column, off_count = 0;
  check(MatGetOwnershipRangeColumn(jacobian, &first_column, &end_column));
  if (off_diagonal_part != nullptr) check(MatGetSize(off_diagonal_part, nullptr, &off_count));
  ISLocalToGlobalMapping to_global;
  check(DMGetLocalToGlobalMapping(da, &to_global));
  PetscInt gxs, gys, gxm;
  check(DMDAGetGhostCorners(da, &gxs, &gys, nullptr, &gxm, nullptr, nullptr));
  const PetscInt *ia, *ja, *ib = nullptr, *jb = nullptr;
  PetscInt rows;
  PetscBool done;
  PetscBool done_off = PETSC_TRUE;
  check(MatGetRowIJ(diagonal_part, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ia, &ja, &done));
  if (off_diagonal_part != nullptr)
    check(MatGetRowIJ(off_diagonal_part, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ib, &jb, &done_off));
  std::vector<std::int64_t> offsets(coupled_pattern.size() * kCouplings * 3, 0);
  bool found_all = done && done_off;
  // The place of column `column` in row `row` of a part, if there with the next two.
  const auto place = [](const PetscInt* i, const PetscInt* j, PetscInt row, PetscInt column) {
    const PetscInt* end = j + i[row + 1];
    const PetscInt* at = std::lower_bound(j + i[row], end, column);
    return end - at >= 3 && at[0] == column && at[1] == column + 1 && at[2] == column + 2
               ? std::optional<std::int64_t>(at - j)
               : std::nullopt;
  };
  for (int l = bl.l0; l < bl.l1 && found_all; ++l)
    for (int k = bl.k0; k < bl.k1 && found_all; ++k) {
      const auto owned = static_cast<std::size_t>((l - bl.l0) * bl.owned_k() + (k - bl.k0));
      for (int c = 0; c < kCouplings && found_all; ++c) {
        if (!(coupled_pattern[owned] & (1u << c))) continue;
        const PetscInt local = (l + c / 5 - 2 - gys) * gxm + (k + c % 5 - 2 - gxs);
        PetscInt global;
        check(ISLocalToGlobalMappingApplyBlock(to_global, 1, &local, &global));
        const PetscInt column = 3 * global;
        for (int i = 0; i < 3 && found_all; ++i) {
          const auto row = static_cast<PetscInt>(3 * owned + i);
          std::optional<std::int64_t> at;
          if (column >= first_column && column < end_column) {
            at = place(ia, ja, row, column - first_column);
          } else if (off_diagonal_part != nullptr) {
            const PetscInt* compressed =
                std::lower_bound(columns_off, columns_off + off_count, column);
            if (compressed != columns_off + off_count && *compressed == column)
              if (const auto in_row = place(ib, jb, row, compressed - columns_off))
                at = -*in_row - 1;
          }
          found_all = at.has_value();
          if (found_all) offsets[(owned * kCouplings + c) * 3 + i] = *at;
        }
      }
    }
  if (done)
    check(MatRestoreRowIJ(diagonal_part, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ia, &ja, &done));
  if (off_diagonal_part != nullptr && done_off)
    check(MatRestoreRowIJ(off_diagonal_part, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ib, &jb,
                          &done_off));
  if (found_all) block_offsets = std::move(offsets);
}

void SemiImplicitSolver::linearise(const Field<Vec3>& r) {
  Impl& s = *impl_;
  const auto start = std::chrono::steady_clock::now();
  if (s.exact) {
    s.assemble_hessians(r);
    // The rigid motions at rⁿ are what the elastic part leaves free: algebraic multigrid
    // (gamg) builds its coarse spaces from them.
    s.copy_in(r, s.x);
    MatNullSpace rigid;
    check(MatNullSpaceCreateRigidBody(s.x, &rigid));
    check(MatSetNearNullSpace(s.system, rigid));
    check(MatNullSpaceDestroy(&rigid));
  } else {
    s.copy_in(r, s.x);
    // The colouring writes only the entries it computes; start from a clean matrix.
    check(MatZeroEntries(s.jacobian));
    check(MatFDColoringApply(s.jacobian, s.colouring, s.x, nullptr));
  }
  s.built = true;
  s.fresh = true;
  s.stats.jacobians += 1;
  s.stats.jacobian_seconds += seconds_since(start);
}

bool SemiImplicitSolver::needs_jacobian(long step) const {
  const Impl& s = *impl_;
  return !s.built || step % s.jacobian_every == 0;
}

std::optional<std::string> SemiImplicitSolver::solve(
    const VelocityTerms& terms, const Field<Vec3>* normals, const Field<Vec3>& rhs,
    const Field<Vec3>& guess, const std::vector<Constraints::NodeState>& held,
    const Field<Vec3>& positions, double end_time, Field<Vec3>& delta) {
  Impl& s = *impl_;
  const Block& bl = *s.block;
  const auto start = std::chrono::steady_clock::now();
  const double dt = s.dt;
  const double diagonal = 1.0 / (dt * dt) + terms.damping / (2.0 * dt);

  s.copy_in(rhs, s.b);
  check(VecPointwiseMult(s.b, s.b, s.weights));
  s.copy_in(guess, s.delta);
  if (s.second_order) {
    // −½ W J d: the force at the mean of rⁿ⁺¹ and rⁿ⁻¹ (docs/semi-implicit.md).
    check(MatMult(s.jacobian, s.delta, s.x));
    check(VecAXPY(s.b, -0.5, s.x));
  }
  // W [(1/Δt² + D/(2Δt)) I + F/(2Δt) n nᵀ] − W J (½ W J in the second-order step): the
  // centred velocity terms of docs/equations.md §4, each row times its node's weight (1 with a
  // differenced J).
  check(MatCopy(s.jacobian, s.system, SAME_NONZERO_PATTERN));
  check(MatScale(s.system, s.second_order ? -0.5 : -1.0));
  check(VecCopy(s.weights, s.shift));
  check(VecScale(s.shift, diagonal));
  check(MatDiagonalSet(s.system, s.shift, ADD_VALUES));
  if (terms.fluid > 0.0) {
    for (int l = bl.l0; l < bl.l1; ++l)
      for (int k = bl.k0; k < bl.k1; ++k) {
        const double weight = terms.fluid / (2.0 * dt) * s.row_weight(k, l);
        const Vec3 n = (*normals)(k, l);
        MatStencil node[3];
        PetscScalar block[9];
        for (int a = 0; a < 3; ++a) {
          node[a] = MatStencil{0, l, k, a};
          for (int c = 0; c < 3; ++c) block[3 * a + c] = weight * n[a] * n[c];
        }
        check(MatSetValuesStencil(s.system, 3, node, 3, node, block, ADD_VALUES));
      }
    check(MatAssemblyBegin(s.system, MAT_FINAL_ASSEMBLY));
    check(MatAssemblyEnd(s.system, MAT_FINAL_ASSEMBLY));
  }

  // Held components: δ is the held value at the step's end less rⁿ (0 for a still fix), rows
  // and columns replaced by the diagonal (symmetry kept for cg), the other rows' right-hand
  // side moved by the columns' share of that δ.
  std::vector<PetscInt> held_rows;
  for (const Constraints::NodeState& node : held)
    if (bl.owns(node.k, node.l))
      for (int c = 0; c < 3; ++c)
        if (node.held & (1u << c)) {
          const PetscInt row = s.first_row + s.offset(node.k, node.l, c);
          held_rows.push_back(row);
          const double held_delta = node.position(c, end_time) - positions(node.k, node.l)[c];
          check(VecSetValue(s.delta, row, held_delta, INSERT_VALUES));
        }
  check(VecAssemblyBegin(s.b));
  check(VecAssemblyEnd(s.b));
  check(VecAssemblyBegin(s.delta));
  check(VecAssemblyEnd(s.delta));
  check(MatZeroRowsColumns(s.system, static_cast<PetscInt>(held_rows.size()), held_rows.data(),
                           diagonal, s.delta, s.b));

  const auto setup_start = std::chrono::steady_clock::now();
  // A step that reuses J keeps the preconditioner built with it.
  check(KSPSetReusePreconditioner(s.ksp, s.fresh ? PETSC_FALSE : PETSC_TRUE));
  s.fresh = false;
  check(KSPSetUp(s.ksp));
  s.stats.setup_seconds += seconds_since(setup_start);
  check(KSPSolve(s.ksp, s.b, s.delta));
  KSPConvergedReason reason;
  PetscInt iterations;
  check(KSPGetConvergedReason(s.ksp, &reason));
  check(KSPGetIterationNumber(s.ksp, &iterations));
  s.copy_out(s.delta, delta);
  s.stats.solves += 1;
  s.stats.iterations += iterations;
  s.stats.most_iterations = std::max<long>(s.stats.most_iterations, iterations);
  s.stats.solve_seconds += seconds_since(start);
  if (reason < 0) {
    KSPType ksp_type;
    PCType pc_type;
    PC pc;
    check(KSPGetType(s.ksp, &ksp_type));
    check(KSPGetPC(s.ksp, &pc));
    check(PCGetType(pc, &pc_type));
    // On large sheets block Jacobi stops converging, and smoothed aggregation fails once the
    // sheet has deformed, where BoomerAMG does not (docs/semi-implicit.md, "Preconditioners,
    // against grid size").
    const std::string hint =
        s.exact && std::string(pc_type) != PCHYPRE
            ? "; on a large sheet, [time.solver] ksp = \"cg\" with pc = \"hypre\" converges "
              "(docs/semi-implicit.md)"
            : "";
    return fmt::format("the linear solver did not converge ({} after {} iterations, {} with {}){}",
                       KSPConvergedReasons[reason], iterations, ksp_type, pc_type, hint);
  }
  return std::nullopt;
}

const LinearSolveStats& SemiImplicitSolver::stats() const { return impl_->stats; }

KrylovChoice default_linear_solver(bool exact_jacobian, long nodes, bool have_hypre) {
  // benchmarks/results/semi-implicit-grids-vm-2026-12-05.md: from 240² block Jacobi needs
  // hundreds of iterations a step, and does not converge on 480².
  constexpr long kMultigridNodes = 240L * 240L;
  if (exact_jacobian && have_hypre && nodes >= kMultigridNodes) return {"cg", "hypre"};
  return {"gmres", "bjacobi"};
}

void add_petsc_options(const std::string& options) {
  // Given before PETSc starts, as PETSC_OPTIONS is, so that it reads its start-up's own
  // options (-log_view, -info, ...): given after, -log_view's log was never begun, and
  // PetscFinalize's refusal to print it ended the run, its output written, in an abort. Given
  // again once it has started, so that they stay on top of PETSC_OPTIONS.
  check(PetscOptionsInsertString(nullptr, options.c_str()));
  start_petsc();
  check(PetscOptionsInsertString(nullptr, options.c_str()));
}

void finalize_petsc() {
  if (!petsc_started_here) return;
  PetscBool finalized = PETSC_FALSE;
  // After the run, whose output is written: a failure here is reported, not an abort.
  if (PetscFinalized(&finalized) == 0 && finalized) return;
  if (const PetscErrorCode code = PetscFinalize(); code != 0)
    fmt::print(stderr, "warning: PETSc's finalisation failed (PETSc error {})\n",
               static_cast<int>(code));
}

}  // namespace cosserat
