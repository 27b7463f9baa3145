# KMBVH_RECORD_RAYS (cmake -P): the scene client runs under the preload library recording
# its queries, and `kmbvh trace --rays-file` then traces them with kmbvh and Embree: both
# query kinds present, as many rays as the limit allowed, no mismatch, the same answers one
# query at a time in the recorded order (--in-order); and with KMBVH_RECORD_EVERY, one query
# in N of the same run.
#   -DCLIENT=kmbvh_scene_client -DPRELOAD=libkmbvh_preload.so -DKMBVH=kmbvh -DSCENE=file|default -DWORK=dir
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
set(rays "${WORK}/rays.bin")
set(limit 3000)
execute_process(COMMAND ${CMAKE_COMMAND} -E env "LD_PRELOAD=${PRELOAD}" "KMBVH_RECORD_RAYS=${rays}"
                        "KMBVH_RECORD_LIMIT=${limit}" "${CLIENT}" trace "${SCENE}" "${WORK}/hits.bin"
                RESULT_VARIABLE rc ERROR_VARIABLE log)
message("${log}")
if(NOT rc EQUAL 0 OR NOT log MATCHES "${limit} queries recorded to")
  message(FATAL_ERROR "the client under the preload failed or recorded no queries (${rc})")
endif()
file(SIZE "${rays}" bytes)
math(EXPR expected "8 + 36 * ${limit}")  # the magic, then one 36-byte record a query
if(NOT bytes EQUAL expected)
  message(FATAL_ERROR "${rays}: ${bytes} bytes, expected ${expected}")
endif()
# KMBVH_RECORD_EVERY=7: the queries 0, 7, 14, ... of the same run (the client queries from one
# thread, in one order), record for record.
set(sampled "${WORK}/sampled.bin")
set(every 7)
set(kept 100)
execute_process(COMMAND ${CMAKE_COMMAND} -E env "LD_PRELOAD=${PRELOAD}" "KMBVH_RECORD_RAYS=${sampled}"
                        "KMBVH_RECORD_LIMIT=${kept}" "KMBVH_RECORD_EVERY=${every}" "${CLIENT}" trace "${SCENE}"
                        "${WORK}/hits_sampled.bin"
                RESULT_VARIABLE rc ERROR_VARIABLE log)
if(NOT rc EQUAL 0 OR NOT log MATCHES "${kept} queries recorded to")
  message(FATAL_ERROR "the client recording one query in ${every} failed or recorded too few (${rc}): ${log}")
endif()
file(READ "${sampled}" magic LIMIT 8 HEX)
file(READ "${rays}" magic_all LIMIT 8 HEX)
if(NOT magic STREQUAL magic_all)
  message(FATAL_ERROR "${sampled}: no ray file's magic")
endif()
math(EXPR last "${kept} - 1")
foreach(i RANGE ${last})
  math(EXPR at "8 + 36 * ${i}")
  math(EXPR at_all "8 + 36 * ${i} * ${every}")
  file(READ "${sampled}" record OFFSET ${at} LIMIT 36 HEX)
  file(READ "${rays}" record_all OFFSET ${at_all} LIMIT 36 HEX)
  if(NOT record STREQUAL record_all)
    message(FATAL_ERROR "sampled record ${i} is not query ${i} * ${every} of the whole recording")
  endif()
endforeach()
execute_process(COMMAND "${KMBVH}" trace "${SCENE}" --rays-file "${rays}" --in-order --compare-embree --runs 1 --json
                        --quiet
                RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "kmbvh trace --rays-file failed (${rc}): ${out}")
endif()
string(JSON mismatches GET "${out}" mismatches)
string(JSON closest GET "${out}" layouts 0 kinds 0 kind)
string(JSON occlusion GET "${out}" layouts 0 kinds 1 kind)
string(JSON n0 GET "${out}" layouts 0 kinds 0 rays)
string(JSON n1 GET "${out}" layouts 0 kinds 1 rays)
math(EXPR traced "${n0} + ${n1}")
if(NOT mismatches EQUAL 0 OR NOT closest STREQUAL "app-closest" OR NOT occlusion STREQUAL "app-occlusion"
   OR NOT traced EQUAL limit)
  message(FATAL_ERROR "expected ${limit} recorded rays of both kinds traced with no mismatch: ${out}")
endif()
# --in-order: every query once more, one at a time in the recorded order, as the batches answer it.
string(JSON in_order GET "${out}" layouts 0 in_order queries)
string(JSON differences GET "${out}" layouts 0 in_order differences)
string(JSON embree_rate GET "${out}" layouts 0 in_order embree_mrays_per_s)
if(NOT in_order EQUAL limit OR NOT differences EQUAL 0 OR NOT embree_rate GREATER 0)
  message(FATAL_ERROR "expected ${limit} queries traced in order by both, as the batches answer them: ${out}")
endif()
# A file that is not a ray file is refused with a message naming it.
execute_process(COMMAND "${KMBVH}" trace default --rays-file "${CMAKE_CURRENT_LIST_FILE}" --quiet
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "not a ray file")
  message(FATAL_ERROR "a file that is not a ray file was not refused (${rc}): ${err}")
endif()
