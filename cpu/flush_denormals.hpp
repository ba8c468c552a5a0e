#pragma once
// Saturated sigmoids produce derivatives below float's normal range, and arithmetic on such
// denormals is many times slower on x86 (a 2D network trained 2-3x slower because of it).
// Flushing them to zero (FTZ and DAZ, a per-thread setting) costs no accuracy that matters
// here; every thread that runs a kernel sets it, so results stay reproducible.
#if defined(__SSE__)
#include <xmmintrin.h>
#endif

namespace yarnhom::cpu {

inline void flush_denormals() {
#if defined(__SSE__)
  _mm_setcsr(_mm_getcsr() | 0x8040);
#endif
}

}  // namespace yarnhom::cpu
