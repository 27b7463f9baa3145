# Instruction set for all host code: x86-64-v2 (SSE4.2), so that one build runs on every
# x86-64 CPU of the last fifteen years, whatever machine built it. What pays for more is
# compiled for more and chosen at run time: the wide traversal has SSE4.2, AVX2 and AVX-512
# kernels (adapters/out/cpu_isa.h). The builders were measured at x86-64-v2 and -v3 on an
# AVX2 machine (conference, 2 threads, `kmbvh build --runs 5`): k-means Q1 and Q3 within
# noise of each other, LBVH about 10% slower at v2. KMBVH_CPU_ARCH=native (or x86-64-v3,
# x86-64-v4) builds for the build machine only; "" keeps the compiler's default. The same
# flag everywhere, so inline functions never differ between objects (the traversal's
# kernels raise it only inside their own target regions).
set(KMBVH_CPU_ARCH "x86-64-v2" CACHE STRING "-march for host code (empty: compiler default)")
if(KMBVH_CPU_ARCH)
  add_compile_options($<$<COMPILE_LANGUAGE:CXX>:-march=${KMBVH_CPU_ARCH}>
                      $<$<COMPILE_LANGUAGE:CUDA>:-Xcompiler=-march=${KMBVH_CPU_ARCH}>)
endif()
message(STATUS "kmbvh: host code for -march=${KMBVH_CPU_ARCH}")

# No floating-point contraction anywhere: g++ in ISO mode (-std=c++17) never contracts, but
# clang fuses a*b+c within an expression by default. The same source then computes other
# rays and other double-precision checks under clang (the sanitizer build) than under g++,
# and the watertight test (cuda/CMakeLists.txt, kmbvh_traversal) needs it off in any case.
add_compile_options($<$<COMPILE_LANGUAGE:CXX>:-ffp-contract=off>)
