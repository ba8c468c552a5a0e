#pragma once
// YARNHOM_HOST_ISA: the target ISA, the compiler and the floating-point model of the
// translation unit that expands it, as a string literal ("x86-64 sse4.2 avx avx2 fma avx512f
// ... biggest-alignment=64 compiler=12.2.0"). A macro, not a function, so that every
// translation unit gets its own: cuda::host_isa() (cuda/host_isa.cu) returns what nvcc's host
// pass saw, and tests/cuda/test_host_isa.cpp compares it with a .cpp file's. Every translation
// unit must see the same (docs/layout.md, "Compiler flags").
//
// No includes and no Eigen: this header is read by nvcc too.

#define YARNHOM_ISA_STR_(x) #x
#define YARNHOM_ISA_STR(x) YARNHOM_ISA_STR_(x)

#if defined(__x86_64__)
#define YARNHOM_ISA_ARCH "x86-64"
#elif defined(__aarch64__)
#define YARNHOM_ISA_ARCH "aarch64"
#else
#define YARNHOM_ISA_ARCH "other"
#endif
#if defined(__SSE4_2__)
#define YARNHOM_ISA_SSE42 " sse4.2"
#else
#define YARNHOM_ISA_SSE42 ""
#endif
#if defined(__AVX__)
#define YARNHOM_ISA_AVX " avx"
#else
#define YARNHOM_ISA_AVX ""
#endif
#if defined(__AVX2__)
#define YARNHOM_ISA_AVX2 " avx2"
#else
#define YARNHOM_ISA_AVX2 ""
#endif
#if defined(__FMA__)
#define YARNHOM_ISA_FMA " fma"
#else
#define YARNHOM_ISA_FMA ""
#endif
#if defined(__F16C__)
#define YARNHOM_ISA_F16C " f16c"
#else
#define YARNHOM_ISA_F16C ""
#endif
#if defined(__AVX512F__)
#define YARNHOM_ISA_AVX512F " avx512f"
#else
#define YARNHOM_ISA_AVX512F ""
#endif
#if defined(__AVX512VL__)
#define YARNHOM_ISA_AVX512VL " avx512vl"
#else
#define YARNHOM_ISA_AVX512VL ""
#endif
#if defined(__AVX512BW__)
#define YARNHOM_ISA_AVX512BW " avx512bw"
#else
#define YARNHOM_ISA_AVX512BW ""
#endif
#if defined(__AVX512DQ__)
#define YARNHOM_ISA_AVX512DQ " avx512dq"
#else
#define YARNHOM_ISA_AVX512DQ ""
#endif
#if defined(__FAST_MATH__)
#define YARNHOM_ISA_FAST_MATH " fast-math"
#else
#define YARNHOM_ISA_FAST_MATH ""
#endif
// The widest alignment the target asks for (GCC, Clang): 16 for SSE, 32 for AVX, 64 for
// AVX-512. Eigen's EIGEN_MAX_ALIGN_BYTES follows the same ISA macros.
#if defined(__BIGGEST_ALIGNMENT__)
#define YARNHOM_ISA_ALIGN " biggest-alignment=" YARNHOM_ISA_STR(__BIGGEST_ALIGNMENT__)
#else
#define YARNHOM_ISA_ALIGN ""
#endif
#if defined(__VERSION__)
#define YARNHOM_ISA_COMPILER " compiler=" __VERSION__
#else
#define YARNHOM_ISA_COMPILER ""
#endif

#define YARNHOM_HOST_ISA                                                                          \
  YARNHOM_ISA_ARCH YARNHOM_ISA_SSE42 YARNHOM_ISA_AVX YARNHOM_ISA_AVX2 YARNHOM_ISA_FMA             \
      YARNHOM_ISA_F16C YARNHOM_ISA_AVX512F YARNHOM_ISA_AVX512VL YARNHOM_ISA_AVX512BW              \
          YARNHOM_ISA_AVX512DQ YARNHOM_ISA_FAST_MATH YARNHOM_ISA_ALIGN YARNHOM_ISA_COMPILER
