#pragma once
// Halo exchange of a block's ghost rings with the up to eight neighbouring blocks (docs/design.md,
// principle 1). Width kGhostWidth = 2, the reach of the force stencil (docs/equations.md §2.4,
// derived in model/cosserat_model.cpp): a node's force reads positions up to two nodes away along
// each axis and diagonally (the box stencil), so the corner blocks are neighbours too. The
// intermediates (resultants, tractions) are recomputed on the ring rather than exchanged, so
// one exchange of positions per force evaluation is all the kernel needs. Ghosts outside the
// grid are never written: the physical-border rules test the global index and do not read them.

#include <mpi.h>

#include <vector>

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/decomposition.hpp"
#include "cosserat/grid/vec3.hpp"

namespace cosserat {

class Halo {
 public:
  Halo(const Decomposition& decomposition, const Block& block, int rank);
  ~Halo();
  Halo(const Halo&) = delete;
  Halo& operator=(const Halo&) = delete;

  // Fills the ghost nodes inside the grid with the owners' values. Collective over the
  // neighbours: every rank calls it for the same field at the same point. Call outside
  // OpenMP parallel regions (MPI_THREAD_FUNNELED). begin() posts the receives, then the sends;
  // the owned nodes may be read (not written) and the ghosts neither until end() returns;
  // exchange() is both. One exchange at a time.
  void begin(Field<Vec3>& field);
  void end();
  void exchange(Field<Vec3>& field) {
    begin(field);
    end();
  }

  // Wall time spent in exchanges so far.
  double seconds() const { return seconds_; }

 private:
  struct Neighbour {
    int rank;
    MPI_Datatype send, receive;  // subarrays of the local field
    int send_tag, receive_tag;
  };

  MPI_Comm comm_;
  MPI_Datatype node_type_;
  std::vector<Neighbour> neighbours_;
  std::vector<MPI_Request> requests_;
  bool in_flight_ = false;
  double started_ = 0.0;
  double seconds_ = 0.0;
};

}  // namespace cosserat
