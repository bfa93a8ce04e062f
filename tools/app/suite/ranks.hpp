// The ranks of a suite run under mpirun, which share out its cases, or one
// rank alone (suite/run.cpp).
#pragma once

#include <cstdlib>

#ifdef MPMVV_HAVE_MPI
// The C API only; OpenMPI's header would pull in its deprecated C++ bindings.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace mpmvv::app::suite_file {

// The ranks of an mpirun, or one rank alone; MPI stays out of a suite run
// without mpirun. MPI_Finalize when the run ends, however it returns.
class Ranks {
 public:
  Ranks() {
#ifdef MPMVV_HAVE_MPI
    under_mpi_ = std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") || std::getenv("PMIX_RANK");
    if (!under_mpi_) return;
    if (MPI_Init(nullptr, nullptr) != MPI_SUCCESS) {
      under_mpi_ = false;
      failed_ = true;
      return;
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &count_);
#endif
  }
  ~Ranks() {
#ifdef MPMVV_HAVE_MPI
    if (under_mpi_) MPI_Finalize();
#endif
  }
  Ranks(const Ranks&) = delete;
  Ranks& operator=(const Ranks&) = delete;

  bool failed() const { return failed_; }
  int rank() const { return rank_; }
  int count() const { return count_; }
  bool first() const { return rank_ == 0; }
  // Rank 0's value of `v` on every rank.
  void share_first(int& v) const {
#ifdef MPMVV_HAVE_MPI
    if (under_mpi_) MPI_Bcast(&v, 1, MPI_INT, 0, MPI_COMM_WORLD);
#else
    (void)v;
#endif
  }
  void wait_for_all() const {
#ifdef MPMVV_HAVE_MPI
    if (under_mpi_) MPI_Barrier(MPI_COMM_WORLD);
#endif
  }

 private:
  bool under_mpi_ = false;
  bool failed_ = false;
  int rank_ = 0;
  int count_ = 1;
};

}  // namespace mpmvv::app::suite_file
