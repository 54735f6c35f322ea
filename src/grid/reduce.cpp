#include "cosserat/grid/reduce.hpp"

#include <vector>

namespace cosserat {

double global_sum(double local, MPI_Comm comm) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  std::vector<double> partials(static_cast<std::size_t>(size));
  MPI_Allgather(&local, 1, MPI_DOUBLE, partials.data(), 1, MPI_DOUBLE, comm);
  double sum = 0.0;
  for (double p : partials) sum += p;
  return sum;
}

double global_max(double local, MPI_Comm comm) {
  double result = local;
  MPI_Allreduce(&local, &result, 1, MPI_DOUBLE, MPI_MAX, comm);
  return result;
}

}  // namespace cosserat
