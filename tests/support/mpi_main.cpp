// GoogleTest entry point for tests that use the solver: the solver's reductions are MPI calls,
// so MPI is initialised around the whole test run (one rank here).
#include <gtest/gtest.h>
#include <mpi.h>

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  const int status = RUN_ALL_TESTS();
  MPI_Finalize();
  return status;
}
