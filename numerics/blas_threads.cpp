#include "numerics/blas_threads.hpp"

#include <dlfcn.h>

#include <cstdio>
#include <string>

namespace yarnhom::numerics {

namespace {
template <class F>
F lookup(const char* name) {
  return reinterpret_cast<F>(dlsym(RTLD_DEFAULT, name));
}
}  // namespace

bool set_blas_threads(int threads) {
  const auto set = lookup<void (*)(int)>("openblas_set_num_threads");
  if (!set || threads < 1) return false;
  set(threads);
  return true;
}

const char* blas_description() {
  static thread_local std::string s;
  const auto config = lookup<char* (*)()>("openblas_get_config");
  const auto nthreads = lookup<int (*)()>("openblas_get_num_threads");
  if (!config || !nthreads) return "reference BLAS (or one yarnhom cannot query)";
  char buf[64];
  std::snprintf(buf, sizeof buf, ", %d thread(s)", nthreads());
  const std::string c = config();  // "OpenBLAS 0.3.21 DYNAMIC_ARCH ... Haswell MAX_THREADS=64"
  s = (c.rfind("OpenBLAS", 0) == 0 ? c : "OpenBLAS " + c) + buf;
  return s.c_str();
}

}  // namespace yarnhom::numerics
