# Instruction set for all host code. The kernels' distance loops vectorise well with AVX2,
# so the default is x86-64-v3 where the build machine has it, and x86-64-v4 (AVX-512) where
# it has that too: the wide traversal's masks and packed-triangle tests run 10-25% faster
# with it (measured with `kmbvh trace`, README). The same flag everywhere, so inline
# functions never differ between objects. KMBVH_CPU_ARCH="" keeps the compiler's.
set(_kmbvh_default_arch "")
if(EXISTS /proc/cpuinfo)
  file(READ /proc/cpuinfo _kmbvh_cpuinfo)
  if(_kmbvh_cpuinfo MATCHES " avx2" AND _kmbvh_cpuinfo MATCHES " fma" AND _kmbvh_cpuinfo MATCHES " bmi2")
    set(_kmbvh_default_arch "x86-64-v3")
    if(_kmbvh_cpuinfo MATCHES " avx512f" AND _kmbvh_cpuinfo MATCHES " avx512bw" AND _kmbvh_cpuinfo MATCHES " avx512cd"
       AND _kmbvh_cpuinfo MATCHES " avx512dq" AND _kmbvh_cpuinfo MATCHES " avx512vl")
      set(_kmbvh_default_arch "x86-64-v4")
    endif()
  endif()
endif()
set(KMBVH_CPU_ARCH "${_kmbvh_default_arch}" CACHE STRING "-march for host code (empty: compiler default)")
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
