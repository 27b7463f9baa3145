# The package as a user meets it: kmbvh installed from BUILD_DIR into a fresh prefix under
# WORK_DIR, then the consumer project (tests/package) configured against that prefix alone,
# built, and run. Any step's failure fails the test with that step's output.
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DGENERATOR=... -P install_and_consume.cmake
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR GENERATOR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "install_and_consume.cmake needs -D${var}=...")
  endif()
endforeach()

function(step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "${what} failed (${code}):\n${out}\n${err}")
  endif()
  message(STATUS "${what}: ok")
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
step("install into ${prefix}" ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")
foreach(file lib/cmake/kmbvh/kmbvhConfig.cmake lib/cmake/kmbvh/kmbvhConfigVersion.cmake include/kmbvh/kmbvh.h
             include/kmbvh/embree.h include/kmbvh/embree_swap.h include/kmbvh/version.h lib/libkmbvh.so
             lib/libkmbvh_embree.so lib/libkmbvh_preload.so)
  if(NOT EXISTS "${prefix}/${file}")
    message(FATAL_ERROR "the install has no ${file}")
  endif()
endforeach()

# Only the prefix: nothing of the source or build tree is on the consumer's paths.
step("configure the consumer" ${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/package" -B "${WORK_DIR}/consumer" -G "${GENERATOR}"
     -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${prefix}"
     "-DKMBVH_SWAP_EXAMPLE=${SOURCE_DIR}/examples/embree_swap/custom_bvh.cpp")
step("build the consumer" ${CMAKE_COMMAND} --build "${WORK_DIR}/consumer")
step("run build_and_trace (kmbvh::kmbvh)" "${WORK_DIR}/consumer/build_and_trace")
message(STATUS "${step_output}")
step("run custom_bvh (kmbvh::embree, the one-line swap)" "${WORK_DIR}/consumer/custom_bvh" 20000)
message(STATUS "${step_output}")

if(EXISTS "${prefix}/bin/kmbvh")  # built with the tools
  step("run the installed kmbvh --version" "${prefix}/bin/kmbvh" --version)
  if(NOT step_output MATCHES "0\\.2")
    message(FATAL_ERROR "the installed kmbvh says '${step_output}', not version 0.2")
  endif()
  # Its images go through the codec module it opens from the prefix's lib folder.
  step("render with the installed kmbvh" "${prefix}/bin/kmbvh" render --width 16 --height 12 --spp 1 --views 0
       --builder Q1 --out "${WORK_DIR}/images" -q)
  file(GLOB images "${WORK_DIR}/images/*.png")
  if(NOT images)
    message(FATAL_ERROR "the installed kmbvh rendered no image into ${WORK_DIR}/images")
  endif()
endif()

# The version file: 0.2 is found, another minor version is not.
file(WRITE "${WORK_DIR}/version_probe/CMakeLists.txt"
     "cmake_minimum_required(VERSION 3.24)\nproject(probe NONE)\nfind_package(kmbvh 0.1 QUIET)\n"
     "if(kmbvh_FOUND)\n  message(FATAL_ERROR \"kmbvh 0.1 was found in a 0.2 install\")\nendif()\n")
step("find_package(kmbvh 0.1) finds nothing" ${CMAKE_COMMAND} -S "${WORK_DIR}/version_probe" -B "${WORK_DIR}/version_probe/build"
     "-DCMAKE_PREFIX_PATH=${prefix}")
