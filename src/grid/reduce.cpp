#include "cosserat/grid/reduce.hpp"

#include "cosserat/grid/block.hpp"

#include <cstring>
#include <limits>
#include <utility>
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

namespace {
// A QuantizedSum's count as raw bytes (MPI has no 128-bit integer type) and its validity as
// one byte more.
constexpr int kPackedBytes = sizeof(QuantizedSum::Count) + 1;

// The reduction of packed sums: integer addition, exact and associative, so the total is the
// same bits whatever order MPI combines the ranks in.
void add_packed(void* in, void* inout, int* length, MPI_Datatype*) {
  const auto* a = static_cast<const unsigned char*>(in);
  auto* b = static_cast<unsigned char*>(inout);
  for (int i = 0; i < *length; ++i, a += kPackedBytes, b += kPackedBytes) {
    QuantizedSum::Count x, y;
    std::memcpy(&x, a, sizeof x);
    std::memcpy(&y, b, sizeof y);
    y += x;
    std::memcpy(b, &y, sizeof y);
    b[sizeof y] = a[sizeof x] != 0 && b[sizeof y] != 0 ? 1 : 0;
  }
}
}  // namespace

double QuantizedSum::global_total(MPI_Comm comm) const {
  // One all-reduce of a type and operation made once a process: the flux form takes the area
  // every damped step (docs/equations.md §3), and an all-gather of every rank's count grows
  // with the ranks.
  static const auto [type, op] = [] {
    MPI_Datatype t;
    MPI_Type_contiguous(kPackedBytes, MPI_BYTE, &t);
    MPI_Type_commit(&t);
    MPI_Op o;
    MPI_Op_create(add_packed, 1, &o);
    return std::pair{t, o};
  }();
  unsigned char local[kPackedBytes], total[kPackedBytes];
  std::memcpy(local, &count_, sizeof(Count));
  local[sizeof(Count)] = valid_ ? 1 : 0;
  MPI_Allreduce(local, total, 1, type, op, comm);
  QuantizedSum sum(quantum_);
  std::memcpy(&sum.count_, total, sizeof(Count));
  sum.valid_ = total[sizeof(Count)] != 0;
  return sum.total();
}

}  // namespace cosserat
