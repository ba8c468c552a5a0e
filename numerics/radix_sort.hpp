#pragma once
// A stable sort of (key, value) pairs by integer key on the OpenMP threads: least-significant-digit
// radix sort, 11-bit digits. For lists the simulator builds at every step (a broad phase's grid
// cells, a matrix's triplets), where a comparison sort or a counting sort with shared atomic
// counters does not scale with the threads.
//
// Each pass: every thread counts the digits of its contiguous part of the list, the places are
// handed out digit by digit and thread by thread (so equal keys keep their order: stable), then
// every thread moves its part. The result depends only on the input, not on the thread count.
#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/raw_vector.hpp"

namespace yarnhom::numerics {

// Sorts key (and val with it) by the key's low `bits` bits (keys must be below 2^bits), stably;
// on the threads when par.
template <class Key, class Val>
void radix_sort(RawVector<Key>& key, RawVector<Val>& val, int bits, bool par) {
  constexpr int kDigit = 11;
  constexpr size_t R = size_t(1) << kDigit;
  const size_t n = key.size();
  RawVector<Key> k2(n);
  RawVector<Val> v2(n);
  const int T = par ? omp_get_max_threads() : 1;
  std::vector<size_t> hist(size_t(T) * R);
  for (int shift = 0; shift < bits; shift += kDigit) {
#pragma omp parallel num_threads(T) if (par)
    {
      const int t = omp_get_thread_num(), nt = omp_get_num_threads();
      const size_t lo = n * size_t(t) / size_t(nt), hi = n * size_t(t + 1) / size_t(nt);
      size_t* h = &hist[size_t(t) * R];
      std::fill(h, h + R, size_t(0));
      for (size_t k = lo; k < hi; ++k) ++h[size_t(key[k] >> shift) & (R - 1)];
#pragma omp barrier
#pragma omp single
      {
        size_t sum = 0;
        for (size_t d = 0; d < R; ++d)
          for (int u = 0; u < nt; ++u) {
            const size_t c = hist[size_t(u) * R + d];
            hist[size_t(u) * R + d] = sum;
            sum += c;
          }
      }
      for (size_t k = lo; k < hi; ++k) {
        const size_t at = h[size_t(key[k] >> shift) & (R - 1)]++;
        k2[at] = key[k];
        v2[at] = val[k];
      }
    }
    key.swap(k2);
    val.swap(v2);
  }
}

// The number of bits of the largest key below `bound` (at least 1).
inline int key_bits(uint64_t bound) {
  int bits = 1;
  while (bits < 64 && (uint64_t(1) << bits) < bound) ++bits;
  return bits;
}

}  // namespace yarnhom::numerics
