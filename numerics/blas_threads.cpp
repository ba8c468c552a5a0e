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
  __builtin_cpu_init();
  const bool avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                      __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl") &&
                      __builtin_cpu_supports("avx512cd");
  const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  const bool amd = __builtin_cpu_is("amd");
  if (fallback) {
    if (avx512 && !amd) return "SkylakeX";
    if (avx2) return amd ? "Zen" : "Haswell";
    return nullptr;
  }
  // An AMD CPU given an AVX-512 set: the AVX2 one (OpenBLAS's Zen) runs CHOLMOD's supernodes faster.
  const bool avx512_set = core == "SkylakeX" || core == "Cooperlake" || core == "SapphireRapids";
  if (amd && avx2 && avx512_set) return "Zen";
#endif
  return nullptr;
}

}  // namespace yarnhom::numerics
