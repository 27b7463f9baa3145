// One macro for code that runs on both sides (the pbrt-v4 convention): kernel bodies are
// written once, compiled by g++ for the CPU backend and by nvcc for the GPU (docs/design.md §3).
#pragma once

#if defined(__CUDACC__)
#define KMBVH_HD __host__ __device__
#define KMBVH_INLINE __forceinline__
#else
#define KMBVH_HD
#define KMBVH_INLINE inline
#endif

// True while nvcc compiles the device side of a translation unit.
#if defined(__CUDA_ARCH__)
#define KMBVH_DEVICE_CODE 1
#else
#define KMBVH_DEVICE_CODE 0
#endif
