#pragma once
// Global reductions with a fixed summation order, so a run repeats bitwise (DESIGN.md
// principle 5): every rank's partial is gathered and summed in rank order on every rank.

#include <mpi.h>

namespace cosserat {

double global_sum(double local, MPI_Comm comm);
double global_max(double local, MPI_Comm comm);

}  // namespace cosserat
