# An unmodified Embree tutorial (embree-tools) under the preload library (cmake -P): the
# image it writes with and without the library must agree, and KMBVH_LOG must show that
# kmbvh answered every ray. Path tracing turns a last-bit difference in a hit point into
# a different path for that sample, so a few pixels may differ: at most FAIL_PERCENT of
# them by more than FAIL (idiff), and the image's mean error stays tiny.
#   -DPROGRAM=... -DARGS="...;..." -DPRELOAD=... -DIDIFF=... -DWORK=dir
#   -DFAIL=0.1 -DFAIL_PERCENT=1 [-DSCENE=file: skipped when absent]
if(SCENE AND NOT EXISTS "${SCENE}")
  message("KMBVH-SKIPPED: scene ${SCENE} is absent (set KMBVH_SCENES_DIR)")
  return()
endif()
file(MAKE_DIRECTORY "${WORK}")
execute_process(COMMAND "${PROGRAM}" ${ARGS} -o "${WORK}/embree.ppm" RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} on Embree failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E env "LD_PRELOAD=${PRELOAD}" KMBVH_LOG=1
                        "${PROGRAM}" ${ARGS} -o "${WORK}/kmbvh.ppm"
                RESULT_VARIABLE rc ERROR_VARIABLE log OUTPUT_QUIET)
message("${log}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} under the preload library failed (${rc})")
endif()
if(NOT log MATCHES "scene path: ([0-9]+) rays answered by kmbvh, ([0-9]+) by Embree")
  message(FATAL_ERROR "KMBVH_LOG has no ray counts")
endif()
if(CMAKE_MATCH_1 EQUAL 0 OR NOT CMAKE_MATCH_2 EQUAL 0)
  message(FATAL_ERROR "expected kmbvh to answer every ray: ${CMAKE_MATCH_1} by kmbvh, ${CMAKE_MATCH_2} by Embree")
endif()
execute_process(COMMAND "${IDIFF}" -fail ${FAIL} -failpercent ${FAIL_PERCENT} -warn ${FAIL} -warnpercent ${FAIL_PERCENT}
                        "${WORK}/embree.ppm" "${WORK}/kmbvh.ppm"
                RESULT_VARIABLE rc OUTPUT_VARIABLE diff)
message("${diff}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the images differ (idiff ${rc})")
endif()
