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
include(${CMAKE_CURRENT_LIST_DIR}/preload_ab.cmake)
kmbvh_run_alone_and_preloaded("${PROGRAM}" ppm "${PROGRAM}" ${ARGS} -o @OUT@)
if(by_kmbvh EQUAL 0 OR NOT by_embree EQUAL 0)
  message(FATAL_ERROR "expected kmbvh to answer every ray: ${by_kmbvh} by kmbvh, ${by_embree} by Embree")
endif()
execute_process(COMMAND "${IDIFF}" -fail ${FAIL} -failpercent ${FAIL_PERCENT} -warn ${FAIL} -warnpercent ${FAIL_PERCENT}
                        "${WORK}/embree.ppm" "${WORK}/kmbvh.ppm"
                RESULT_VARIABLE rc OUTPUT_VARIABLE diff)
message("${diff}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the images differ (idiff ${rc})")
endif()
