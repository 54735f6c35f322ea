#include "cosserat/grid/reduce.hpp"

#include "cosserat/grid/block.hpp"

#include <cstring>
#include <limits>
#include <vector>

namespace cosserat {

double global_sum(double local, MPI_Comm comm) {
  const int size = size_of(comm);
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

double QuantizedSum::total() const {
  if (!valid_) return std::numeric_limits<double>::quiet_NaN();
  return static_cast<double>(count_) * quantum_;
}

double QuantizedSum::global_total(MPI_Comm comm) const {
  // The count travels as raw bytes (MPI has no 128-bit integer type); the validity as one more.
  constexpr std::size_t bytes = sizeof(Count) + 1;
  unsigned char local[bytes];
  std::memcpy(local, &count_, sizeof(Count));
  local[sizeof(Count)] = valid_ ? 1 : 0;
  const int size = size_of(comm);
  std::vector<unsigned char> all(bytes * static_cast<std::size_t>(size));
  MPI_Allgather(local, bytes, MPI_BYTE, all.data(), bytes, MPI_BYTE, comm);
  QuantizedSum sum(quantum_);
  for (int r = 0; r < size; ++r) {
    QuantizedSum part(quantum_);
    std::memcpy(&part.count_, all.data() + bytes * static_cast<std::size_t>(r), sizeof(Count));
    part.valid_ = all[bytes * static_cast<std::size_t>(r) + sizeof(Count)] != 0;
    sum.add(part);
  }
  return sum.total();
}

}  // namespace cosserat
