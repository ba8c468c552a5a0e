#include "numerics/blas_threads.hpp"

#include <dlfcn.h>

#include <cstdio>
#include <cstdlib>
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

const char* blas_kernels_to_request() {
#if defined(__x86_64__)
  if (std::getenv("OPENBLAS_CORETYPE")) return nullptr;
  const auto corename = lookup<char* (*)()>("openblas_get_corename");
  if (!corename) return nullptr;
  const std::string core = corename();
  const bool fallback = core == "Prescott" || core == "Core2" || core == "Penryn" || core == "Nehalem" ||
                        core == "Katmai" || core == "Northwood" || core == "Banias" || core == "unknown";
  if (!fallback) return nullptr;
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512cd"))
    return "SkylakeX";
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "Haswell";
#endif
  return nullptr;
}

}  // namespace yarnhom::numerics
