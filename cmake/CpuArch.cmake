# Instruction set for all host code. The kernels' distance loops vectorise well with AVX2,
# so the default is x86-64-v3 where the build machine has it (the same flag everywhere, so
# inline functions never differ between objects). KMBVH_CPU_ARCH="" keeps the compiler's.
set(_kmbvh_default_arch "")
if(EXISTS /proc/cpuinfo)
  file(READ /proc/cpuinfo _kmbvh_cpuinfo)
  if(_kmbvh_cpuinfo MATCHES " avx2" AND _kmbvh_cpuinfo MATCHES " fma" AND _kmbvh_cpuinfo MATCHES " bmi2")
    set(_kmbvh_default_arch "x86-64-v3")
  endif()
endif()
set(KMBVH_CPU_ARCH "${_kmbvh_default_arch}" CACHE STRING "-march for host code (empty: compiler default)")
if(KMBVH_CPU_ARCH)
  add_compile_options($<$<COMPILE_LANGUAGE:CXX>:-march=${KMBVH_CPU_ARCH}>
                      $<$<COMPILE_LANGUAGE:CUDA>:-Xcompiler=-march=${KMBVH_CPU_ARCH}>)
endif()
message(STATUS "kmbvh: host code for -march=${KMBVH_CPU_ARCH}")
