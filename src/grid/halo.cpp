#include "cosserat/grid/halo.hpp"

#include <array>
#include <cassert>

namespace cosserat {

namespace {

// A message travelling in direction (dk, dl) carries this tag, so a rank that receives from
// its neighbour at (dk, dl) expects the tag of (−dk, −dl).
int direction_tag(int dk, int dl) { return (dk + 1) + 3 * (dl + 1); }

// [start, start + count) along one axis of the owned range [lo, hi): the band of width g next
// to side d of the owned range (d = −1, +1), or the whole range (d = 0); `ghost` selects the
// band outside the owned range instead of inside it.
std::array<int, 2> band(int lo, int hi, int d, int g, bool ghost) {
  if (d == 0) return {lo, hi - lo};
  if (d < 0) return {ghost ? lo - g : lo, g};
  return {ghost ? hi : hi - g, g};
}

}  // namespace

Halo::Halo(const Decomposition& decomposition, const Block& block, int rank) : comm_(block.comm) {
  MPI_Type_contiguous(3, MPI_DOUBLE, &node_type_);
  MPI_Type_commit(&node_type_);
  static_assert(sizeof(Vec3) == 3 * sizeof(double));
  const int i = rank % decomposition.parts_k(), j = rank / decomposition.parts_k();
  const int g = block.ghost;
  // The local array in C order: [l rows][k columns], ghosts included.
  const std::array<int, 2> sizes{block.owned_l() + 2 * g, block.stride()};
  for (int dl = -1; dl <= 1; ++dl)
    for (int dk = -1; dk <= 1; ++dk) {
      if (dk == 0 && dl == 0) continue;
      const int neighbour = decomposition.rank_of(i + dk, j + dl);
      if (neighbour == MPI_PROC_NULL) continue;
      auto subarray = [&](bool ghost) {
        const auto [k, count_k] = band(block.k0, block.k1, dk, g, ghost);
        const auto [l, count_l] = band(block.l0, block.l1, dl, g, ghost);
        const std::array<int, 2> counts{count_l, count_k};
        const std::array<int, 2> starts{l - block.l0 + g, k - block.k0 + g};
        MPI_Datatype type;
        MPI_Type_create_subarray(2, sizes.data(), counts.data(), starts.data(), MPI_ORDER_C,
                                 node_type_, &type);
        MPI_Type_commit(&type);
        return type;
      };
      neighbours_.push_back(Neighbour{neighbour, subarray(false), subarray(true),
                                      direction_tag(dk, dl), direction_tag(-dk, -dl)});
    }
  requests_.resize(2 * neighbours_.size());
}

Halo::~Halo() {
  for (Neighbour& n : neighbours_) {
    MPI_Type_free(&n.send);
    MPI_Type_free(&n.receive);
  }
  MPI_Type_free(&node_type_);
}

void Halo::begin(Field<Vec3>& field) {
  assert(!in_flight_ && "one halo exchange at a time");
  if (neighbours_.empty()) return;
  in_flight_ = true;
  started_ = MPI_Wtime();
  // Send and receive regions are disjoint (owned bands, ghost bands), so all transfers of
  // one field may be in flight at once.
  std::size_t r = 0;
  for (const Neighbour& n : neighbours_)
    MPI_Irecv(field.data(), 1, n.receive, n.rank, n.receive_tag, comm_, &requests_[r++]);
  for (const Neighbour& n : neighbours_)
    MPI_Isend(field.data(), 1, n.send, n.rank, n.send_tag, comm_, &requests_[r++]);
}

void Halo::end() {
  if (!in_flight_) return;
#ifdef NDEBUG
  MPI_Waitall(static_cast<int>(requests_.size()), requests_.data(), MPI_STATUSES_IGNORE);
#else
  // Each receive must be exactly the band the neighbour sent: same node count both ways.
  std::vector<MPI_Status> statuses(requests_.size());
  MPI_Waitall(static_cast<int>(requests_.size()), requests_.data(), statuses.data());
  for (std::size_t i = 0; i < neighbours_.size(); ++i) {
    int count = 0;
    MPI_Get_count(&statuses[i], neighbours_[i].receive, &count);
    assert(count == 1 && "halo band sizes of neighbouring blocks disagree");
  }
#endif
  seconds_ += MPI_Wtime() - started_;
  in_flight_ = false;
}

}  // namespace cosserat
