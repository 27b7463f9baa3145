# One scene-path test (cmake -P): scene_client traces on Embree alone, then under the
# preload library with KMBVH_LOG set; the log must say who answered (EXPECT kmbvh: every
# ray by kmbvh; EXPECT embree: a fallback, every ray by Embree), and the two runs'
# answers must agree (scene_client compare).
#   -DCLIENT=... -DPRELOAD=... -DSCENE=file|default -DWORK=dir -DEXPECT=kmbvh|embree
#   [-DOPTIONS="--filter;--quad"] [-DSKIP_IF_MISSING=ON]
if(SKIP_IF_MISSING AND NOT EXISTS "${SCENE}")
  message("KMBVH-SKIPPED: scene ${SCENE} is absent (set KMBVH_SCENES_DIR)")
  return()
endif()
include(${CMAKE_CURRENT_LIST_DIR}/preload_ab.cmake)
kmbvh_run_alone_and_preloaded(scene_client bin "${CLIENT}" trace "${SCENE}" @OUT@ ${OPTIONS})
if(EXPECT STREQUAL "kmbvh")
  if(by_kmbvh EQUAL 0 OR NOT by_embree EQUAL 0)
    message(FATAL_ERROR "expected kmbvh to answer every ray: ${by_kmbvh} by kmbvh, ${by_embree} by Embree")
  endif()
  set(exact --exact-forms)
else()
  if(NOT by_kmbvh EQUAL 0 OR by_embree EQUAL 0 OR NOT preload_log MATCHES "Embree answers it: ")
    message(FATAL_ERROR "expected a logged fallback to Embree: ${by_kmbvh} by kmbvh, ${by_embree} by Embree")
  endif()
endif()
# A dynamic scene's second commit (the vertices moved) is answered by the first's tree, refitted;
# scattered vertices spoil that tree, and the commit builds a new one (from the meshes the
# refit read: scene_accel.h, CommitMeshes).
if(OPTIONS MATCHES "--dynamic" AND EXPECT STREQUAL "kmbvh" AND NOT preload_log MATCHES "refit of ")
  message(FATAL_ERROR "the dynamic scene's second commit was not refitted:\n${preload_log}")
endif()
if(OPTIONS MATCHES "--scatter" AND EXPECT STREQUAL "kmbvh" AND NOT preload_log MATCHES "built again, not refitted: a refit's SAH")
  message(FATAL_ERROR "the scattered scene's second commit was not built again:\n${preload_log}")
endif()
execute_process(COMMAND "${CLIENT}" compare "${SCENE}" "${WORK}/embree.bin" "${WORK}/kmbvh.bin" ${OPTIONS} ${exact}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the answers differ")
endif()
