#pragma once
// The local block of the global m x n grid that one rank owns, with ghost layers around it
// (docs/design.md, principle 1). Every loop in the solver runs over global indices (k, l) inside
// the block's owned range, so the same code serves one rank and many; physical-border rules test
// the global index, never the block edge.

#include <mpi.h>

#include <algorithm>
#include <cassert>
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

namespace cosserat {

// This process's rank in comm, and comm's size.
inline int rank_in(MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank;
}
inline int size_of(MPI_Comm comm) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  return size;
}

// Ghost width: a node's force reads positions up to two nodes away (docs/equations.md §2.4; the
// derivation is next to the kernel in model/cosserat_model.cpp).
inline constexpr int kGhostWidth = 2;

struct Block {
  MPI_Comm comm = MPI_COMM_WORLD;
  int m = 0, n = 0;    // global grid
  int k0 = 0, k1 = 0;  // owned k range [k0, k1)
  int l0 = 0, l1 = 0;  // owned l range [l0, l1)
  int ghost = kGhostWidth;

  // The whole grid as one block: the decomposition of a single rank.
  static Block whole(int m, int n, MPI_Comm comm = MPI_COMM_WORLD) {
    return Block{comm, m, n, 0, m, 0, n, kGhostWidth};
  }

  int owned_k() const { return k1 - k0; }
  int owned_l() const { return l1 - l0; }
  int stride() const { return owned_k() + 2 * ghost; }
  std::size_t local_size() const {
    return static_cast<std::size_t>(stride()) * (owned_l() + 2 * ghost);
  }
  // Storage index of global node (k, l); x1 (k) is the fastest index.
  std::size_t index(int k, int l) const {
    assert(k >= k0 - ghost && k < k1 + ghost && l >= l0 - ghost && l < l1 + ghost);
    return static_cast<std::size_t>(k - k0 + ghost) +
           static_cast<std::size_t>(l - l0 + ghost) * static_cast<std::size_t>(stride());
  }
  bool owns(int k, int l) const { return k >= k0 && k < k1 && l >= l0 && l < l1; }
};

#if defined(COSSERAT_SMPI)
// The simulated clusters' build (benchmarks/smpi, docs/parallel.md "Simulated clusters"): set,
// every field of every simulated rank lies in SMPI's one folded block (UntouchedAllocator), so
// a thousand ranks' fields fit this machine. Their values are then meaningless, which a study
// that only times the steps allows.
inline bool smpi_fold_fields = false;
#endif

// Leaves an element built without arguments untouched, so that a vector's pages are first
// written, and so placed in memory near the core, by whoever fills it (Field below). Only for
// implicit-lifetime types, whose bytes need no constructor to be a value.
template <class T>
struct UntouchedAllocator : std::allocator<T> {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);
  template <class U>
  struct rebind {
    using other = UntouchedAllocator<U>;
  };
  UntouchedAllocator() = default;
  template <class U>
  UntouchedAllocator(const UntouchedAllocator<U>&) noexcept {}
  template <class U>
  void construct(U*) noexcept {}
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
#if defined(COSSERAT_SMPI)
  T* allocate(std::size_t count) {
    if (!smpi_fold_fields) return std::allocator<T>::allocate(count);
    return static_cast<T*>(SMPI_SHARED_MALLOC(count * sizeof(T)));
  }
  void deallocate(T* p, std::size_t count) {
    if (!smpi_fold_fields) return std::allocator<T>::deallocate(p, count);
    SMPI_SHARED_FREE(p);
  }
#endif
};

// One value per node of a block, ghosts included, in one contiguous array. Its rows are zeroed
// by the threads that later sweep them (static schedule over rows, as every sweep uses), so
// on a machine with several memory domains each thread's rows sit in its own.
template <class T>
class Field {
 public:
  Field() = default;
  explicit Field(const Block& block) : block_(&block), data_(block.local_size()) {
    const int rows = block.owned_l() + 2 * block.ghost;
    const auto stride = static_cast<std::size_t>(block.stride());
    T* data = data_.data();
#pragma omp parallel for schedule(static)
    for (int row = 0; row < rows; ++row)
      std::fill_n(data + static_cast<std::size_t>(row) * stride, stride, T{});
  }

  T& operator()(int k, int l) { return data_[block_->index(k, l)]; }
  const T& operator()(int k, int l) const { return data_[block_->index(k, l)]; }
  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }
  const Block& block() const { return *block_; }
  void swap(Field& other) noexcept {
    std::swap(block_, other.block_);
    data_.swap(other.data_);
  }
  // The values of a field of a block of the same shape, this field keeping its own block: a
  // copy (operator=) takes the other's, which may have ended with the run that made it.
  void assign_values(const Field& other) {
    if (other.data_.size() != data_.size())
      throw std::logic_error("Field::assign_values: the fields' blocks differ in size");
    std::copy(other.data_.begin(), other.data_.end(), data_.begin());
  }

 private:
  const Block* block_ = nullptr;
  std::vector<T, UntouchedAllocator<T>> data_;
};

}  // namespace cosserat
