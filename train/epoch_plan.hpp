#pragma once
// What one epoch of one network does, independent of the backend: the shuffled order of the
// training points and the batches cut from it (PyTorch DataLoader with shuffle=True,
// drop_last=False: the last batch may be short). Both backends use these functions, so that
// they see the same batches.
#include <cstdint>
#include <vector>

#include "core/offdomain.hpp"
#include "core/rng.hpp"

namespace yarnhom {

// Fisher-Yates with the counter-based generator: a permutation of 0..n-1 for (key, epoch).
YH_HD inline void shuffled_order(uint64_t key, int epoch, int n, int* order) {
  for (int i = 0; i < n; ++i) order[i] = i;
  const uint64_t k = rng_key(key, kRngShuffle, uint64_t(epoch));
  for (int i = n - 1; i > 0; --i) {
    const int j = static_cast<int>(rng_uniform(k, uint64_t(i)) * (i + 1));
    const int t = order[i];
    order[i] = order[j];
    order[j] = t;
  }
}

// The stream of a batch's off-domain points.
YH_HD inline uint64_t batch_offdomain_key(uint64_t key, int epoch, int batch) {
  return rng_key(key, kRngOffDomain, uint64_t(epoch), uint64_t(batch));
}

inline int num_batches(int n, int batch_size) { return (n + batch_size - 1) / batch_size; }

}  // namespace yarnhom
