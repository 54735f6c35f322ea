// GoogleTest entry point for the tests that run under mpiexec with several ranks. Every rank
// runs every test; the tests reduce what they compare over all ranks before asserting, so all
// ranks reach the same verdict and none is left waiting in a collective call. Rank 0 alone
// prints.
#include <gtest/gtest.h>
#include <mpi.h>

#if defined(COSSERAT_TRAP_FPE)
#include <cfenv>
#endif

#include "cosserat/baseline/semi_implicit.hpp"

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
#if defined(COSSERAT_TRAP_FPE)
  // As the cosserat executable does: a NaN, infinity or division by zero in the solver stops
  // the test with SIGFPE at the operation that made it. After MPI_Init, whose libraries are
  // not ours to trap; OpenMP's threads, started later, inherit the setting.
  feenableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
#endif
  ::testing::InitGoogleTest(&argc, argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) {
    ::testing::TestEventListeners& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  const int status = RUN_ALL_TESTS();
  cosserat::finalize_petsc();
  MPI_Finalize();
  return status;
}
