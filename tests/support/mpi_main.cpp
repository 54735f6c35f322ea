// GoogleTest entry point for tests that use the solver: the solver's reductions are MPI calls,
// so MPI is initialised around the whole test run (one rank here).
#include <gtest/gtest.h>
#include <mpi.h>

#if defined(COSSERAT_TRAP_FPE)
#include <cfenv>
#endif

#include "cosserat/baseline/semi_implicit.hpp"

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
#if defined(COSSERAT_TRAP_FPE)
  // As the cosserat executable does: a NaN, infinity or division by zero in the solver stops
  // the test with SIGFPE at the operation that made it. After MPI_Init, whose libraries are
  // not ours to trap; OpenMP's threads, started later, inherit the setting.
  feenableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
#endif
  ::testing::InitGoogleTest(&argc, argv);
  const int status = RUN_ALL_TESTS();
  cosserat::finalize_petsc();
  MPI_Finalize();
  return status;
}
