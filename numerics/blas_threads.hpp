#pragma once
// Threads of the BLAS under CHOLMOD's supernodal factorization (the simulator's and the yarn
// strip's sparse solves). Debian's libblas.so.3 is an
// alternative: the reference BLAS (single-threaded, no control) or OpenBLAS (scripts/install-deps.sh
// installs it; ~5x faster factorizations at 16k triangles, docs/benchmarks.md). OpenBLAS starts
// one thread per core and its idle workers spin for a while after each call, competing with the
// OpenMP element loop that follows on a machine of few cores, so `sim` and `strip` set their
// number themselves (strip, 2 cores, a 3 x 3-tile stockinette strip: 12.0 s with OpenBLAS at 2
// threads, 7.4 s at 1, the same iterates; docs/benchmarks.md). Looked up at run time (dlsym), so
// that the build does not depend on which BLAS is installed.
namespace yarnhom::numerics {

// Sets OpenBLAS's thread count; returns false (and does nothing) when the BLAS loaded is not
// OpenBLAS.
bool set_blas_threads(int threads);

// "OpenBLAS <config>, N thread(s)" or "reference BLAS (or unknown)".
const char* blas_description();

// OpenBLAS's DYNAMIC_ARCH picks its kernels from the CPU's family and model numbers, and two
// of its picks cost our factorizations time:
// - a CPU it does not know (a virtual machine's "Intel(R) Xeon(R) Processor", a newer model than
//   the library) gets the oldest x86-64 kernels, "Prescott" (SSE3), whatever the CPU supports.
//   On such a machine with AVX-512 the 16k-triangle drape's factorization took 303 ms instead
//   of 173 ms with the SkylakeX kernels (docs/benchmarks.md);
// - an AMD CPU with AVX-512 (Zen 4 and 5) gets the AVX-512 kernels of Intel's cores
//   ("Cooperlake", "SkylakeX"), whose blocking suits large matrices: on the 2-core machine's
//   Zen 5 the 16k drape's factorization (CHOLMOD's supernodes, most of them small) took
//   122 ms with them and 111 ms with the AVX2 set of OpenBLAS's "Zen" target.
// This returns the kernel set to ask for instead: on a fallback, "SkylakeX" (AVX-512
// F/BW/DQ/VL/CD on Intel), else "Zen" (AMD) or "Haswell" (Intel) with AVX2 and FMA; on an AMD
// CPU given an AVX-512 set, "Zen". nullptr otherwise (not OpenBLAS, a kernel set that is
// right already, or OPENBLAS_CORETYPE set, which a user may use to choose). The library
// reads OPENBLAS_CORETYPE when it is loaded, so the program must set it and start again
// (tools/cli/main.cpp).
const char* blas_kernels_to_request();

}  // namespace yarnhom::numerics
