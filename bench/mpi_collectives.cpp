// The collectives of a distributed pass, alone (docs/distributed.md, issue 38): what the design
// photonbound uses moves per pass (every rank's photon hits to every rank, the new radii to
// every rank, the states to rank 0 when it develops) and what the alternative design moves (the
// pass sums of every pixel, reduced and scattered to the owners of pixel blocks), timed on
// dummy arrays of the real sizes. Medians of REPS; rank 0 prints.
//   mpirun -np K build/bench/photonbound-mpi-collectives [PIXELS [HITS [REPS]]]
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

constexpr int kHitBytes = 52;     // sizeof(pb::PhotonHit)
constexpr int kStateBytes = 208;  // sizeof(pb::PointState)
constexpr int kSumDoubles = 10;   // pb::PassSums: phi, phi_lap_r2, phi_half (3 each), count

template <class F>
double median_seconds(int reps, F&& f) {
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = MPI_Wtime();
    f();
    double dt = MPI_Wtime() - t0, slowest = 0.0;
    MPI_Allreduce(&dt, &slowest, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    t.push_back(slowest);
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// An all-gather (or a gather to rank 0) of `total` items of `bytes` bytes split evenly.
double gather(long total, int bytes, int reps, bool to_all, int rank, int ranks) {
  std::vector<int> counts(ranks), at(ranks);
  for (int r = 0; r < ranks; ++r) {
    at[r] = int(total * r / ranks);
    counts[r] = int(total * (r + 1) / ranks) - at[r];
  }
  MPI_Datatype type;
  MPI_Type_contiguous(bytes, MPI_BYTE, &type);
  MPI_Type_commit(&type);
  std::vector<char> mine(size_t(counts[rank]) * size_t(bytes), 1);
  std::vector<char> all(to_all || rank == 0 ? size_t(total) * size_t(bytes) : 0);
  const double s = median_seconds(reps, [&] {
    if (to_all)
      MPI_Allgatherv(mine.data(), counts[rank], type, all.data(), counts.data(), at.data(), type,
                     MPI_COMM_WORLD);
    else
      MPI_Gatherv(mine.data(), counts[rank], type, all.data(), counts.data(), at.data(), type, 0,
                  MPI_COMM_WORLD);
  });
  MPI_Type_free(&type);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const long pixels = argc > 1 ? std::atol(argv[1]) : 1920L * 1080L;
  const long hits = argc > 2 ? std::atol(argv[2]) : 1000000L;
  const int reps = argc > 3 ? std::atoi(argv[3]) : 9;

  const double t_hits = gather(hits, kHitBytes, reps, true, rank, ranks);
  const double t_radii = gather(pixels, 4, reps, true, rank, ranks);
  const double t_states = gather(pixels, kStateBytes, reps, false, rank, ranks);
  // The alternative: every rank's pass sums of every pixel, summed and scattered by block.
  const long per_rank = (pixels + ranks - 1) / ranks;
  std::vector<double> sums(size_t(per_rank) * size_t(ranks) * kSumDoubles, 1.0);
  std::vector<double> mine(size_t(per_rank) * kSumDoubles);
  const double t_sums = median_seconds(reps, [&] {
    MPI_Reduce_scatter_block(sums.data(), mine.data(), int(per_rank * kSumDoubles), MPI_DOUBLE,
                             MPI_SUM, MPI_COMM_WORLD);
  });

  if (rank == 0) {
    const double k = double(ranks);
    std::printf("%d ranks, %ld pixels, %ld photon hits per pass; medians of %d (slowest rank)\n",
                ranks, pixels, hits, reps);
    std::printf("  %-44s %9.2f MB received per rank %8.2f ms\n", "hits to every rank (Allgatherv)",
                double(hits) * kHitBytes * (k - 1) / k / 1e6, 1e3 * t_hits);
    std::printf("  %-44s %9.2f MB received per rank %8.2f ms\n", "radii to every rank (Allgatherv)",
                double(pixels) * 4 * (k - 1) / k / 1e6, 1e3 * t_radii);
    std::printf("  %-44s %9.2f MB received by rank 0 %8.2f ms\n", "states to rank 0 (Gatherv)",
                double(pixels) * kStateBytes * (k - 1) / k / 1e6, 1e3 * t_states);
    std::printf("  %-44s %9.2f MB sent per rank     %8.2f ms\n",
                "alternative: pass sums (Reduce_scatter_block)",
                double(pixels) * kSumDoubles * 8 * (k - 1) / k / 1e6, 1e3 * t_sums);
  }
  MPI_Finalize();
  return 0;
}
