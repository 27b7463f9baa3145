# One A/B-mode test (cmake -P): a program runs under the preload library with KMBVH_AB=1
# and KMBVH_AB_REPORT, and its JSON report must say what EXPECT says:
#   zero       compared >= MIN_COMPARED, no mismatch
#   hit_miss, distance, primitive (with KMBVH_AB_PERTURB in ENV): mismatches of that kind,
#              recorded in full; `kmbvh trace --replay REPORT` (REPLAY: the
#              kmbvh binary) finds Embree's recorded answers again and no mismatch
#   fallback   a scene Embree answers, reported with its reason and not compared
#   builds     rtcBuildBVH built by both (the program: kmbvh_example_custom_bvh_embree, run
#              with KMBVH_LOG=1): both trees measured; the tree the program counted itself is
#              the answering system's, and kmbvh's measured tree is the one its build logged
# With FILTER_CALLS=kmbvh|embree (scene_client --filter), the application's filter
# functions must have run as often as they do when that system answers alone.
#   -DPROGRAM=... "-DARGS=...;..." -DPRELOAD=... -DWORK=dir "-DENV=VAR=VALUE;..." -DEXPECT=...
#   [-DMIN_COMPARED=N] [-DREPLAY=kmbvh] [-DFILTER_CALLS=kmbvh|embree] [-DSCENE=file: skipped when absent]
#   [-DEXT=ppm: the extension of the program's output file, @OUT@ in ARGS]
cmake_policy(SET CMP0057 NEW)  # if(... IN_LIST ...)
if(NOT EXT)
  set(EXT out)
endif()
if(SCENE AND NOT EXISTS "${SCENE}")
  message("KMBVH-SKIPPED: scene ${SCENE} is absent (set KMBVH_SCENES_DIR)")
  return()
endif()
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
set(report "${WORK}/ab.json")
list(TRANSFORM ARGS REPLACE "^@OUT@$" "${WORK}/ab.${EXT}" OUTPUT_VARIABLE ab_args)
execute_process(COMMAND ${CMAKE_COMMAND} -E env "LD_PRELOAD=${PRELOAD}" KMBVH_AB=1 "KMBVH_AB_REPORT=${report}" ${ENV}
                        "${PROGRAM}" ${ab_args}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE log)
message("${log}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} under the preload library in A/B mode failed (${rc})")
endif()
if(NOT log MATCHES "A/B total: ([0-9]+) queries compared, ([0-9]+) mismatches")
  message(FATAL_ERROR "no A/B summary on stderr")
endif()
file(READ "${report}" json)
string(JSON compared GET "${json}" compared)
string(JSON mismatches GET "${json}" mismatches)

# Sums over every scene and form: mismatches by kind, fallback scenes, rays Embree answered alone.
set(hit_miss 0)
set(distance 0)
set(primitive 0)
set(first_kinds "")
set(fallbacks 0)
set(embree_only 0)
set(saved "")
string(JSON scenes LENGTH "${json}" scenes)
math(EXPR last_scene "${scenes} - 1")
foreach(s RANGE ${last_scene})
  if(scenes EQUAL 0)
    break()
  endif()
  string(JSON by GET "${json}" scenes ${s} answered_by)
  if(by STREQUAL "embree")
    math(EXPR fallbacks "${fallbacks} + 1")
  endif()
  string(JSON file ERROR_VARIABLE no_file GET "${json}" scenes ${s} scene_file)
  if(NOT no_file AND NOT saved)
    set(saved "${file}")
  endif()
  string(JSON forms LENGTH "${json}" scenes ${s} forms)
  if(forms EQUAL 0)
    continue()
  endif()
  math(EXPR last_form "${forms} - 1")
  foreach(f RANGE ${last_form})
    foreach(kind hit_miss distance primitive embree_only)
      string(JSON n GET "${json}" scenes ${s} forms ${f} ${kind})
      math(EXPR ${kind} "${${kind}} + ${n}")
    endforeach()
    string(JSON first LENGTH "${json}" scenes ${s} forms ${f} first_mismatches)
    if(first GREATER 0)
      string(JSON kind GET "${json}" scenes ${s} forms ${f} first_mismatches 0 kind)
      list(APPEND first_kinds ${kind})
    endif()
  endforeach()
endforeach()
message("A/B report: ${compared} compared, ${mismatches} mismatches (${hit_miss} hit_miss, ${distance} distance, "
        "${primitive} primitive), ${fallbacks} fallback scenes, ${embree_only} rays by Embree alone")

if(EXPECT STREQUAL "zero")
  if(NOT mismatches EQUAL 0 OR compared LESS MIN_COMPARED)
    message(FATAL_ERROR "expected at least ${MIN_COMPARED} queries compared and no mismatch")
  endif()
elseif(EXPECT STREQUAL "builds")
  string(JSON builds LENGTH "${json}" builds)
  string(JSON answer GET "${json}" answer)
  if(builds EQUAL 0)
    message(FATAL_ERROR "no rtcBuildBVH in the report")
  endif()
  foreach(side kmbvh embree)
    foreach(field inner_nodes leaves depth sah)
      string(JSON ${side}_${field} GET "${json}" builds 0 ${side} ${field})
    endforeach()
  endforeach()
  if(NOT out MATCHES ": ([0-9]+) nodes, ([0-9]+) leaves" OR NOT CMAKE_MATCH_1 EQUAL ${answer}_inner_nodes
     OR NOT CMAKE_MATCH_2 EQUAL ${answer}_leaves)
    message(FATAL_ERROR "the program counted another tree (${CMAKE_MATCH_1} nodes, ${CMAKE_MATCH_2} leaves) than "
                        "${answer}'s (${${answer}_inner_nodes} nodes, ${${answer}_leaves} leaves)")
  endif()
  if(NOT log MATCHES "rtcBuildBVH: [^\n]*, SAH ([0-9.]+), ([0-9]+) nodes, ([0-9]+) leaves, depth ([0-9]+)")
    message(FATAL_ERROR "no KMBVH_LOG line of kmbvh's build")
  endif()
  set(logged "${CMAKE_MATCH_1} ${CMAKE_MATCH_2} ${CMAKE_MATCH_3} ${CMAKE_MATCH_4}")
  if(NOT log MATCHES "A/B   kmbvh \\([^)]*\\): [0-9.]+ ms, SAH ([0-9.]+), ([0-9]+) nodes, ([0-9]+) leaves \\([^)]*\\), depth ([0-9]+)")
    message(FATAL_ERROR "no A/B line of kmbvh's build")
  endif()
  set(measured "${CMAKE_MATCH_1} ${CMAKE_MATCH_2} ${CMAKE_MATCH_3} ${CMAKE_MATCH_4}")
  if(NOT logged STREQUAL measured)
    message(FATAL_ERROR "kmbvh's tree as the A/B mode measured it (${measured}) is not the one it built (${logged})")
  endif()
  if(embree_leaves EQUAL 0 OR embree_inner_nodes EQUAL 0)
    message(FATAL_ERROR "Embree's tree was not measured")
  endif()
elseif(EXPECT STREQUAL "fallback")
  if(fallbacks EQUAL 0 OR NOT compared EQUAL 0 OR embree_only EQUAL 0 OR NOT log MATCHES "Embree answers it \\(")
    message(FATAL_ERROR "expected a fallback scene, reported with its reason and not compared")
  endif()
else()
  if(${${EXPECT}} EQUAL 0 OR NOT EXPECT IN_LIST first_kinds)
    message(FATAL_ERROR "expected mismatches of kind ${EXPECT}, recorded in full (first kinds: ${first_kinds})")
  endif()
  if(NOT saved OR NOT EXISTS "${saved}")
    message(FATAL_ERROR "the scene of the mismatches was not saved beside the report")
  endif()
  # The perturbation spoilt kmbvh's answers in the application; replayed (on the scene the
  # report saved, which the replay finds by itself), kmbvh agrees and Embree answers as it
  # did there.
  execute_process(COMMAND "${REPLAY}" trace --replay "${report}" --layout bvh2,bvh8 --quiet
                  RESULT_VARIABLE rc OUTPUT_VARIABLE replayed)
  message("${replayed}")
  if(NOT rc EQUAL 0 OR NOT replayed MATCHES "([0-9]+) of ([0-9]+) rays: Embree's answer as reported; 0 mismatches now"
     OR NOT CMAKE_MATCH_1 EQUAL CMAKE_MATCH_2)
    message(FATAL_ERROR "the replay of the recorded rays did not reproduce them (${rc})")
  endif()
endif()

if(FILTER_CALLS)
  # The same client answered by one system alone: Embree alone, or kmbvh alone (the plain preload).
  list(TRANSFORM ARGS REPLACE "^@OUT@$" "${WORK}/alone.${EXT}" OUTPUT_VARIABLE alone_args)
  if(FILTER_CALLS STREQUAL "embree")
    execute_process(COMMAND "${PROGRAM}" ${alone_args} RESULT_VARIABLE rc OUTPUT_VARIABLE alone)
  else()
    execute_process(COMMAND ${CMAKE_COMMAND} -E env "LD_PRELOAD=${PRELOAD}" "${PROGRAM}" ${alone_args}
                    RESULT_VARIABLE rc OUTPUT_VARIABLE alone)
  endif()
  if(NOT rc EQUAL 0 OR NOT alone MATCHES "([0-9]+) filter calls")
    message(FATAL_ERROR "the run answered by ${FILTER_CALLS} alone failed (${rc})")
  endif()
  set(expected_calls ${CMAKE_MATCH_1})
  if(NOT out MATCHES "([0-9]+) filter calls" OR NOT CMAKE_MATCH_1 EQUAL expected_calls)
    message(FATAL_ERROR "filter functions ran ${CMAKE_MATCH_1} times in A/B mode, ${expected_calls} times when "
                        "${FILTER_CALLS} answers alone")
  endif()
  if(FILTER_CALLS STREQUAL "embree" AND compared EQUAL 0)
    message(FATAL_ERROR "with Embree answering, queries that reach no filtered candidate must be compared")
  endif()
endif()
