#include "dist/mpi_exchange.h"

#ifdef PHOTONBOUND_MPI

#include "render/pass_stages.h"
#include "util/timer.h"

#include <mpi.h>

#include <climits>
#include <cstdlib>
#include <stdexcept>

namespace pb {

namespace {

// Whether a launcher started this process as one of a job's ranks (Open MPI, MPICH/Hydra,
// PMIx, Slurm's srun).
bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "PMI_RANK"})
    if (std::getenv(v)) return true;
  return false;
}

void check(int rc, const char* what) {
  if (rc != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed");
}

int as_count(size_t n, const char* what) {
  if (n > size_t(INT_MAX))
    throw std::length_error(std::string("MPI: ") + what + ": more than 2^31 items in one exchange");
  return int(n);
}

// A contiguous MPI type of `bytes` bytes, so that counts are in items (2^31 items, not bytes).
class ItemType {
 public:
  explicit ItemType(size_t bytes) {
    check(MPI_Type_contiguous(as_count(bytes, "item size"), MPI_BYTE, &type_),
          "MPI_Type_contiguous");
    check(MPI_Type_commit(&type_), "MPI_Type_commit");
  }
  ~ItemType() { MPI_Type_free(&type_); }
  ItemType(const ItemType&) = delete;
  ItemType& operator=(const ItemType&) = delete;
  MPI_Datatype get() const { return type_; }

 private:
  MPI_Datatype type_ = MPI_DATATYPE_NULL;
};

class MpiExchange final : public Exchange {
 public:
  using Exchange::Exchange;

  void all_hits(std::vector<PhotonHit>& hits) override {
    const auto t0 = Clock::now();
    const int k = ranks();
    const long long mine = (long long)hits.size();
    std::vector<long long> counts(size_t(k), 0);
    check(MPI_Allgather(&mine, 1, MPI_LONG_LONG, counts.data(), 1, MPI_LONG_LONG, MPI_COMM_WORLD),
          "MPI_Allgather (hit counts)");
    const size_t ks = size_t(k);
    std::vector<int> n(ks, 0), at(ks, 0);
    size_t total = 0;
    for (int r = 0; r < k; ++r) {
      at[size_t(r)] = as_count(total, "photon hits");
      n[size_t(r)] = as_count(size_t(counts[size_t(r)]), "photon hits");
      total += size_t(counts[size_t(r)]);
    }
    as_count(total, "photon hits");
    received_.resize(total);  // kept from pass to pass: a fresh array costs its page faults
    const ItemType type(sizeof(PhotonHit));
    check(MPI_Allgatherv(hits.data(), n[size_t(rank())], type.get(), received_.data(), n.data(),
                         at.data(), type.get(), MPI_COMM_WORLD),
          "MPI_Allgatherv (photon hits)");
    hits.swap(received_);
    this->hits.bytes += uint64_t(total - size_t(mine)) * sizeof(PhotonHit);
    this->hits.seconds += seconds_since(t0);
  }

  uint64_t sum(uint64_t value) override {
    unsigned long long in = value, out = 0;
    check(MPI_Allreduce(&in, &out, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, MPI_COMM_WORLD),
          "MPI_Allreduce (sum)");
    return out;
  }

  float max(float value) override {
    float out = 0.0f;
    check(MPI_Allreduce(&value, &out, 1, MPI_FLOAT, MPI_MAX, MPI_COMM_WORLD),
          "MPI_Allreduce (max)");
    return out;
  }

  // Point to point, straight from and into the arrays: each rank's whole chunks are one strided
  // MPI type (chunk c is rank c mod K's) and a last, partial chunk one more message; nothing is
  // packed or staged (a staged copy of 1080p's states cost 0.7 s of page faults per collect).
  void share_owned(void* data, size_t item_bytes, size_t n, bool to_all) override {
    const auto t0 = Clock::now();
    const int k = ranks(), me = rank();
    char* items = static_cast<char*>(data);
    const size_t chunk_bytes = kStageChunk * item_bytes;
    const size_t whole = n / kStageChunk, tail_items = n % kStageChunk;
    const int tail_owner = int(whole % size_t(k));
    std::vector<MPI_Datatype> types(size_t(k), MPI_DATATYPE_NULL);
    std::vector<int> chunks(size_t(k), 0);
    for (int r = 0; r < k; ++r) {
      chunks[size_t(r)] = whole > size_t(r)
                              ? as_count((whole - size_t(r) + size_t(k) - 1) / size_t(k), "chunks")
                              : 0;
      if (chunks[size_t(r)] == 0) continue;
      check(MPI_Type_vector(chunks[size_t(r)], as_count(chunk_bytes, "chunk bytes"),
                            as_count(size_t(k) * chunk_bytes, "chunk stride"), MPI_BYTE,
                            &types[size_t(r)]),
            "MPI_Type_vector");
      check(MPI_Type_commit(&types[size_t(r)]), "MPI_Type_commit");
    }
    std::vector<MPI_Request> requests;
    uint64_t received = 0;
    auto post = [&](int r, int peer, bool send) {
      auto op = [&](void* at, int count, MPI_Datatype type, int tag) {
        requests.emplace_back();
        if (send)
          check(MPI_Isend(at, count, type, peer, tag, MPI_COMM_WORLD, &requests.back()),
                "MPI_Isend (states)");
        else
          check(MPI_Irecv(at, count, type, peer, tag, MPI_COMM_WORLD, &requests.back()),
                "MPI_Irecv (states)");
      };
      if (chunks[size_t(r)] > 0) {
        op(items + size_t(r) * chunk_bytes, 1, types[size_t(r)], 1);
        if (!send) received += uint64_t(chunks[size_t(r)]) * chunk_bytes;
      }
      if (tail_items > 0 && r == tail_owner) {
        op(items + whole * chunk_bytes, as_count(tail_items * item_bytes, "tail bytes"), MPI_BYTE,
           2);
        if (!send) received += tail_items * item_bytes;
      }
    };
    for (int peer = 0; peer < k; ++peer) {
      if (peer == me) continue;
      if (to_all || me == 0) post(peer, peer, false);  // peer's items, from peer
      if (to_all || peer == 0) post(me, peer, true);   // mine, to peer
    }
    check(MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE), "MPI_Waitall");
    for (MPI_Datatype& t : types)
      if (t != MPI_DATATYPE_NULL) MPI_Type_free(&t);
    states.bytes += received;
    states.seconds += seconds_since(t0);
  }

  FollowerCommand command(FollowerCommand c) override {
    int value = int(c);
    check(MPI_Bcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD), "MPI_Bcast (command)");
    return FollowerCommand(value);
  }

 private:
  std::vector<PhotonHit> received_;
};

}  // namespace

MpiSession::MpiSession(int& argc, char**& argv) {
  if (!launched_by_mpi()) return;
  int provided = 0;
  // Only the main thread calls MPI (the pass's workers and the checkpoint writer never do).
  check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  initialised_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks_);
}

MpiSession::~MpiSession() {
  if (initialised_) MPI_Finalize();
}

std::unique_ptr<Exchange> MpiSession::exchange() const {
  if (!distributed()) return nullptr;
  return std::make_unique<MpiExchange>(rank_, ranks_);
}

void MpiSession::abort(int code) const {
  if (initialised_) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

std::string mpi_library_version() {
  char text[MPI_MAX_LIBRARY_VERSION_STRING];
  int len = 0;
  MPI_Get_library_version(text, &len);
  std::string s(text, size_t(len));
  const size_t end = s.find_first_of(",\n");
  return end == std::string::npos ? s : s.substr(0, end);
}

}  // namespace pb

#else  // a build without MPI: one process, always

#include <cstdlib>

namespace pb {

MpiSession::MpiSession(int&, char**&) {}
MpiSession::~MpiSession() = default;
std::unique_ptr<Exchange> MpiSession::exchange() const { return nullptr; }
void MpiSession::abort(int code) const { std::exit(code); }
std::string mpi_library_version() { return ""; }

}  // namespace pb

#endif
