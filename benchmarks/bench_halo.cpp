// Halo micro-benchmark: the time of one exchange of a position field (two ghost rings, up to
// eight neighbours) on the split Decomposition::choose makes of an N x N grid over the ranks
// of mpirun, for N = 256, 1024, 4096. Not a Google Benchmark: every rank must run the same
// number of exchanges, so the repetitions are fixed. Rank 0 prints one JSON object per grid
// with the median over 7 batches of the batch mean (the slowest rank's), and the bytes the
// busiest rank receives per exchange.
//   mpirun -np P bench_halo [exchanges per batch = 200]

#include <mpi.h>

#include <algorithm>
#include <cstdlib>
#include <vector>

#include <fmt/format.h>

#include "cosserat/grid/decomposition.hpp"
#include "cosserat/grid/halo.hpp"

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const int per_batch = argc > 1 ? std::atoi(argv[1]) : 200;
  constexpr int batches = 7;
  for (const int nodes : {256, 1024, 4096}) {
    const auto d = cosserat::Decomposition::choose(nodes, nodes, ranks);
    const cosserat::Block block = d.block(rank, MPI_COMM_WORLD);
    cosserat::Halo halo(d, block, rank);
    cosserat::Field<cosserat::Vec3> r(block);
    for (int l = block.l0; l < block.l1; ++l)
      for (int k = block.k0; k < block.k1; ++k) r(k, l) = {double(k), double(l), 0.0};
    // Ghost nodes this rank receives: its ghost rings inside the grid.
    const int g = block.ghost;
    const long k_span = std::min(block.k1 + g, block.m) - std::max(block.k0 - g, 0);
    const long l_span = std::min(block.l1 + g, block.n) - std::max(block.l0 - g, 0);
    const long received = k_span * l_span - long(block.owned_k()) * block.owned_l();
    long most_received = 0;
    MPI_Reduce(&received, &most_received, 1, MPI_LONG, MPI_MAX, 0, MPI_COMM_WORLD);

    halo.exchange(r);  // first-use costs (connection set-up) out of the timing
    std::vector<double> batch_means;
    for (int b = 0; b < batches; ++b) {
      MPI_Barrier(MPI_COMM_WORLD);
      const double start = MPI_Wtime();
      for (int i = 0; i < per_batch; ++i) halo.exchange(r);
      const double mean = (MPI_Wtime() - start) / per_batch;
      double slowest = 0.0;
      MPI_Allreduce(&mean, &slowest, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
      batch_means.push_back(slowest);
    }
    std::sort(batch_means.begin(), batch_means.end());
    if (rank == 0)
      fmt::print(R"({{"nodes": {}, "ranks": {}, "split": [{}, {}], "received_bytes": {}, )"
                 R"("exchange_seconds": {:.6e}, "min_seconds": {:.6e}, "max_seconds": {:.6e}}})"
                 "\n",
                 nodes, ranks, d.parts_k(), d.parts_l(), most_received * 24,
                 batch_means[batches / 2], batch_means.front(), batch_means.back());
  }
  MPI_Finalize();
  return 0;
}
