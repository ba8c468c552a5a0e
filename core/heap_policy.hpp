#pragma once
// How the process's heap treats freed memory, for the long Newton solves (yarn strips, the
// continuum simulator).
//
// Why: every Newton iteration allocates and frees the same large arrays (the per-thread
// Hessian values, CHOLMOD's factor and workspace: tens of MB). glibc's malloc hands blocks
// above its mmap threshold back to the kernel on free and trims the heap's top above its trim
// threshold, so each iteration can fault the same memory in again, page by page, zero-filled:
// measured on the paper's stockinette strip at 100 % (59 iterations, the factor then 40 MB),
// 815,000 minor page faults and 12.7 s of the run's 34 s in the kernel; with this policy 33,000
// and 25 s (docs/benchmarks.md). Keeping freed memory in the heap costs at most the run's peak
// footprint, which it reaches anyway.
namespace yarnhom {

// Makes glibc's malloc keep freed memory for reuse (no mmap for large blocks, no trimming);
// returns false, doing nothing, elsewhere than glibc.
bool retain_freed_memory();

}  // namespace yarnhom
