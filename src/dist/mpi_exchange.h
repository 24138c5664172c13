// The MPI side of a distributed render (render/exchange.h): MPI itself is used in this folder
// only, and only in a build that found it (PHOTONBOUND_MPI).
#pragma once

#include "render/exchange.h"

#include <memory>
#include <string>

namespace pb {

// MPI for the life of the process, when it runs under mpirun (or another MPI launcher); a
// plain start does not initialise MPI at all (a singleton MPI_Init costs time and may fail in
// a container without a launcher).
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  // Whether this process is one of several ranks (an -np 1 run is one process).
  bool distributed() const { return ranks_ > 1; }
  int rank() const { return rank_; }
  int ranks() const { return ranks_; }
  // The exchange of this session's ranks; null when not distributed.
  std::unique_ptr<Exchange> exchange() const;
  // Ends every rank with `code` (MPI_Abort): one rank's failure must not leave the others
  // waiting in a collective.
  [[noreturn]] void abort(int code) const;

 private:
  bool initialised_ = false;
  int rank_ = 0, ranks_ = 1;
};

// "Open MPI v4.1.4" or the like: the library this build runs with; empty in a build without
// MPI.
std::string mpi_library_version();

}  // namespace pb
