# Thrust for the CPU backend (docs/design.md §3), compiled by g++ with the OpenMP device system.
# KMBVH_THRUST picks the copy: "cccl" is CUDA's CCCL (3.x, the same Thrust nvcc uses),
# "system" is Debian's libthrust-dev (1.17); "auto" prefers CCCL when it is installed.
set(KMBVH_THRUST "auto" CACHE STRING "Thrust for the CPU backend: auto, cccl or system")
set(_kmbvh_cccl_dir "")
foreach(_dir "${CUDAToolkit_INCLUDE_DIRS}/cccl" /usr/local/cuda/include/cccl)
  if(EXISTS "${_dir}/thrust/version.h")
    set(_kmbvh_cccl_dir "${_dir}")
    break()
  endif()
endforeach()

if(KMBVH_THRUST STREQUAL "cccl" OR (KMBVH_THRUST STREQUAL "auto" AND _kmbvh_cccl_dir))
  if(NOT _kmbvh_cccl_dir)
    message(FATAL_ERROR "KMBVH_THRUST=cccl but no CCCL was found under the CUDA toolkit")
  endif()
  set(KMBVH_THRUST_INCLUDE_DIR "${_kmbvh_cccl_dir}")
elseif(KMBVH_THRUST STREQUAL "system" OR KMBVH_THRUST STREQUAL "auto")
  find_path(KMBVH_THRUST_INCLUDE_DIR thrust/version.h PATHS /usr/include NO_DEFAULT_PATH)
  if(NOT KMBVH_THRUST_INCLUDE_DIR)
    message(FATAL_ERROR "No Thrust found: install libthrust-dev (scripts/install-deps.sh does)")
  endif()
else()
  message(FATAL_ERROR "KMBVH_THRUST must be auto, cccl or system")
endif()

file(STRINGS "${KMBVH_THRUST_INCLUDE_DIR}/thrust/version.h" _kmbvh_thrust_line
     REGEX "^#define THRUST_VERSION [0-9]+")
string(REGEX MATCH "[0-9]+" _kmbvh_thrust_version "${_kmbvh_thrust_line}")
math(EXPR _major "${_kmbvh_thrust_version} / 100000")
math(EXPR _minor "(${_kmbvh_thrust_version} / 100) % 1000")
message(STATUS "kmbvh: CPU backend uses Thrust ${_major}.${_minor} from ${KMBVH_THRUST_INCLUDE_DIR} (OpenMP device system)")

add_library(kmbvh_thrust_omp INTERFACE)
target_include_directories(kmbvh_thrust_omp SYSTEM INTERFACE "${KMBVH_THRUST_INCLUDE_DIR}")
target_compile_definitions(kmbvh_thrust_omp INTERFACE THRUST_DEVICE_SYSTEM=THRUST_DEVICE_SYSTEM_OMP)
target_link_libraries(kmbvh_thrust_omp INTERFACE OpenMP::OpenMP_CXX)
if(KMBVH_SANITIZERS MATCHES "undefined")
  # CCCL's thrust::reference dispatches on a null policy pointer inside Thrust (element
  # access, copy_if, scans), not in kmbvh's kernels: every file compiled against Thrust on
  # OpenMP keeps every other undefined-behaviour check.
  target_compile_options(kmbvh_thrust_omp INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-fno-sanitize=null>)
endif()
