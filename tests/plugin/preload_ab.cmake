# What the preload tests (cmake -P scripts) share: a program run on Embree alone, then
# under the preload library with KMBVH_LOG set.
#   kmbvh_run_alone_and_preloaded(<what> <ext> <command...>)
# The command has @OUT@ where each run's output file goes: ${WORK}/embree.<ext>, then
# ${WORK}/kmbvh.<ext>. Fails, naming <what>, when a run fails or the log has no ray counts;
# sets preload_log, by_kmbvh and by_embree (rays each answered) in the caller. PRELOAD_ENV:
# more VAR=value for the preloaded run.
function(kmbvh_run_alone_and_preloaded what ext)
  file(MAKE_DIRECTORY "${WORK}")
  list(TRANSFORM ARGN REPLACE "^@OUT@$" "${WORK}/embree.${ext}" OUTPUT_VARIABLE alone)
  list(TRANSFORM ARGN REPLACE "^@OUT@$" "${WORK}/kmbvh.${ext}" OUTPUT_VARIABLE preloaded)
  execute_process(COMMAND ${alone} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} on Embree failed (${rc})")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} -E env "LD_PRELOAD=${PRELOAD}" KMBVH_LOG=1 ${PRELOAD_ENV} ${preloaded}
                  RESULT_VARIABLE rc ERROR_VARIABLE log)
  message("${log}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} under the preload library failed (${rc})")
  endif()
  if(NOT log MATCHES "scene path: ([0-9]+) rays answered by kmbvh, ([0-9]+) by Embree")
    message(FATAL_ERROR "KMBVH_LOG has no ray counts")
  endif()
  set(preload_log "${log}" PARENT_SCOPE)
  set(by_kmbvh ${CMAKE_MATCH_1} PARENT_SCOPE)
  set(by_embree ${CMAKE_MATCH_2} PARENT_SCOPE)
endfunction()
