# Warnings for kmbvh's own targets (not for third-party headers, which come in as SYSTEM).
function(kmbvh_warnings target)
  target_compile_options(${target} PRIVATE $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wno-unknown-pragmas>)
endfunction()
