// One macro for code that runs on both sides (the pbrt-v4 convention): kernel bodies are
// written once, compiled by g++ for the CPU backend and by nvcc for the GPU (docs/design.md §3).
#pragma once

#if defined(__CUDACC__)
#define KMBVH_HD __host__ __device__
#define KMBVH_INLINE __forceinline__
#define KMBVH_FORCE_INLINE __forceinline__
#define KMBVH_COLD static __noinline__  // static: one copy a translation unit, no ODR clash
#else
#define KMBVH_HD
#define KMBVH_INLINE inline
#define KMBVH_FORCE_INLINE inline __attribute__((always_inline))
#define KMBVH_COLD inline __attribute__((noinline, cold))
#endif

// KMBVH_FORCE_INLINE: inlined whatever the compiler's heuristics say, for the double-precision
// checks the CPU traversal makes on most rays (watertight.h). Out of line they are compiled
// for the file's baseline instruction set, so every call from the AVX kernels spilled the
// kernel's vector registers: inlined, spot's primary rays ran 0.75 -> 0.90 of Embree's speed
// (docs/design.md §9, instruction sets). KMBVH_COLD: the opposite, for a rare path inside
// such a check (the needles' double-precision test), kept out of the kernel's loop.

// True while nvcc compiles the device side of a translation unit.
#if defined(__CUDA_ARCH__)
#define KMBVH_DEVICE_CODE 1
#else
#define KMBVH_DEVICE_CODE 0
#endif
