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
# --one-tree is this script's: the preload builds a dynamic scene's meshes under one tree
# (KMBVH_MESH_TREES=0) instead of a tree per mesh.
set(PRELOAD_ENV "")
if(OPTIONS MATCHES "--one-tree")
  list(REMOVE_ITEM OPTIONS --one-tree)
  set(PRELOAD_ENV KMBVH_MESH_TREES=0)
endif()
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
# A dynamic scene's second commit (the vertices moved) is answered by the first's trees, a tree
# per mesh, refitted; scattered vertices spoil some of them, and the commit builds those again
# (from the meshes the refit read: scene_accel.h, CommitMeshes), unless the application asked
# for refits (--refit-quality). Under one tree (--one-tree) the whole scene is built again.
if(OPTIONS MATCHES "--dynamic" AND EXPECT STREQUAL "kmbvh" AND NOT PRELOAD_ENV AND NOT preload_log MATCHES "refit of ")
  message(FATAL_ERROR "the dynamic scene's second commit was not refitted:\n${preload_log}")
endif()
# A scene of RTC_BUILD_QUALITY_LOW is built with LBVH (plugin/README.md, "Build quality").
if(OPTIONS MATCHES "--low" AND EXPECT STREQUAL "kmbvh" AND NOT preload_log MATCHES "kmbvh: scene [^\n]*: lbvh, ")
  message(FATAL_ERROR "the LOW scene was not built with lbvh:\n${preload_log}")
endif()
if(OPTIONS MATCHES "--scatter" AND EXPECT STREQUAL "kmbvh")
  if(PRELOAD_ENV)
    set(expected "built again, not refitted: a refit's SAH")
  elseif(OPTIONS MATCHES "--refit-quality")
    set(expected "refit of [^\n]*\\(3 of 3 meshes; 0 built again\\)")
  else()
    set(expected "refit of [^\n]*\\([0-2] of 3 meshes; [1-3] built again\\)")
  endif()
  if(NOT preload_log MATCHES "${expected}")
    message(FATAL_ERROR "the scattered scene's second commit was not built again as expected (${expected}):\n${preload_log}")
  endif()
endif()
# A static scene built three times (--recommit): the first build keeps no memory for the
# next, the second keeps it, and the third allocates nothing (scene_registry.cpp).
if(OPTIONS MATCHES "--recommit" AND EXPECT STREQUAL "kmbvh")
  string(REGEX MATCHALL "triangles in [0-9]+ meshes[^\n]*, [0-9]+ backend allocations" builds "${preload_log}")
  list(LENGTH builds count)
  if(NOT count EQUAL 3)
    message(FATAL_ERROR "expected three builds of the recommitted scene:\n${preload_log}")
  endif()
  list(GET builds 0 first)
  list(GET builds 1 second)
  list(GET builds 2 third)
  if(first MATCHES ", 0 backend allocations" OR second MATCHES ", 0 backend allocations"
     OR NOT third MATCHES ", 0 backend allocations")
    message(FATAL_ERROR "expected backend allocations in the first two builds and none in the third:\n${preload_log}")
  endif()
endif()
execute_process(COMMAND "${CLIENT}" compare "${SCENE}" "${WORK}/embree.bin" "${WORK}/kmbvh.bin" ${OPTIONS} ${exact}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the answers differ")
endif()
