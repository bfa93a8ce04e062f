// OpenMP helpers. Without OpenMP everything runs on one thread.
#pragma once

#include <array>
#include <cstddef>
#include <utility>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mpmvv {

inline int max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

inline int thread_id() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

inline void set_threads(int n) {
#ifdef _OPENMP
  if (n > 0) omp_set_num_threads(n);
#else
  (void)n;
#endif
}

// The iterations [first, last) of a loop over [begin, end) that `omp for
// schedule(static)` gives the calling thread: contiguous blocks in thread
// order, the first (end - begin) % T threads one iteration longer (libgomp's
// split). A thread that walks its block in its own steps (by lanes, say) then
// visits the same particles in the same order as the `omp for` would.
inline std::pair<std::size_t, std::size_t> static_block(std::size_t begin, std::size_t end) {
#ifdef _OPENMP
  const std::size_t threads = std::size_t(omp_get_num_threads()), t = std::size_t(omp_get_thread_num());
#else
  const std::size_t threads = 1, t = 0;
#endif
  const std::size_t n = end > begin ? end - begin : 0;
  std::size_t q = n / threads, r = n % threads;
  if (t < r) {
    r = 0;
    ++q;
  }
  const std::size_t first = begin + q * t + r;
  return {first, first + q};
}

// Called by every thread of a parallel region once each thread has filled its
// own buffer (after the barrier of the loop that filled them): adds the first
// `count` entries of every buffer into the first buffer, the entries shared
// out over the threads.
inline void sum_into_first(std::vector<std::vector<double>>& per_thread, std::size_t count) {
#pragma omp for schedule(static)
  for (std::size_t i = 0; i < count; ++i)
    for (std::size_t t = 1; t < per_thread.size(); ++t) per_thread[0][i] += per_thread[t][i];
}

// Sums over a parallel loop with the same bits for a given thread count:
// each thread sums its own iterations in order and keeps its K sums, and
// total() adds the threads' sums in thread order. (An OpenMP reduction adds
// them in the order the threads finish: the same with one or two threads, a
// sum of two being the same either way, but with three or more the last
// bits change from run to run.)
//   ThreadOrderedSums<1> sums;
//   #pragma omp parallel
//   { double own = 0.0;
//     #pragma omp for schedule(static)
//     for (...) own += ...;
//     sums.keep({own}); }
template <std::size_t K>
class ThreadOrderedSums {
 public:
  ThreadOrderedSums() : per_thread_(std::size_t(max_threads()), std::array<double, K>{}) {}
  // Called by each thread of the region, once.
  void keep(const std::array<double, K>& own) { per_thread_[std::size_t(thread_id())] = own; }
  std::array<double, K> total() const {
    std::array<double, K> sum{};
    for (const std::array<double, K>& own : per_thread_)
      for (std::size_t k = 0; k < K; ++k) sum[k] += own[k];
    return sum;
  }

 private:
  std::vector<std::array<double, K>> per_thread_;
};

}  // namespace mpmvv
