#pragma once
// Global reductions with a fixed summation order, so a run repeats bitwise (docs/design.md,
// principle 5): every rank's partial is gathered and summed in rank order on every rank.

#include <mpi.h>

#include <cstdint>

namespace cosserat {

double global_sum(double local, MPI_Comm comm);
double global_max(double local, MPI_Comm comm);

// A sum of non-negative doubles counted in integer multiples of a quantum. Integer addition is
// associative, so the total is the same bitwise whatever the order of the terms: the same for
// any decomposition and thread count, not only for a given one. Used for the total area S,
// which enters the trajectory (docs/equations.md §3), so that P ranks follow one rank's trajectory
// bitwise. Each term is rounded to the nearest quantum; a term that is not finite or too
// large for 62 bits makes the total NaN.
class QuantizedSum {
 public:
  __extension__ using Count = __int128;

  explicit QuantizedSum(double quantum) : quantum_(quantum), per_quantum_(1.0 / quantum) {}

  void add(double term) {
    const double q = term * per_quantum_ + 0.5;
    if (q >= 0.0 && q < 0x1p62)
      count_ += static_cast<std::int64_t>(q);
    else
      valid_ = false;
  }
  void add(const QuantizedSum& other) {
    count_ += other.count_;
    valid_ = valid_ && other.valid_;
  }

  // The total over all ranks of comm; collective.
  double global_total(MPI_Comm comm) const;
  double total() const;

 private:
  double quantum_, per_quantum_;
  Count count_ = 0;
  bool valid_ = true;
};

}  // namespace cosserat
