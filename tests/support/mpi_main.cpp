// GoogleTest entry point for tests that use the solver: the solver's reductions are MPI calls,
// so MPI is initialised around the whole test run (one rank here).
#include <gtest/gtest.h>
#include <mpi.h>

#include "cosserat/baseline/semi_implicit.hpp"

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  const int status = RUN_ALL_TESTS();
  cosserat::finalize_petsc();
  MPI_Finalize();
  return status;
}
