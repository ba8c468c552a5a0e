#pragma once
// A scope in which OpenMP runs every parallel region on the calling thread alone, for calls
// into libraries whose own OpenMP would fight ours.
//
// Why: Debian 12's CHOLMOD (SuiteSparse 5) runs loops of its supernodal factorization in
// OpenMP regions whose thread count was fixed when it was compiled (num_threads(4), which
// overrides omp_set_num_threads). On a 2-core machine with our element loops on 2 threads,
// libgomp then grew and shrank its pool around every factorization (two thread creations per
// factorization) and 4 threads shared 2 cores: 21,000 futex calls per factorization. Measured
// on the paper's stockinette strip at 100 % (59 factorizations, docs/benchmarks.md): 6.5 s of
// factorization and 3.2 s in the kernel; with its regions capped at 2 threads (OMP_THREAD_LIMIT)
// 3.3 s and 0.9 s; serial (this scope) see docs/benchmarks.md.
//
// How: max-active-levels 0 makes every parallel region inactive (one thread) until the scope
// ends; it is a process-wide setting, so open the scope only from serial code.
#ifdef _OPENMP
#include <omp.h>
#endif

namespace yarnhom::numerics {

class SerialOpenMP {
 public:
#ifdef _OPENMP
  SerialOpenMP() : saved_(omp_get_max_active_levels()) { omp_set_max_active_levels(0); }
  ~SerialOpenMP() { omp_set_max_active_levels(saved_); }
#else
  SerialOpenMP() = default;
#endif
  SerialOpenMP(const SerialOpenMP&) = delete;
  SerialOpenMP& operator=(const SerialOpenMP&) = delete;

 private:
#ifdef _OPENMP
  int saved_ = 1;
#endif
};

}  // namespace yarnhom::numerics
