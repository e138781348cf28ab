# One place for compiler warnings, applied per target with generator expressions.
function(strata_set_warnings target)
  target_compile_options(${target} PRIVATE
    $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow=local -Wnon-virtual-dtor
                                  -Wold-style-cast -Wcast-align -Wnull-dereference>
    $<$<AND:$<BOOL:${STRATA_WARNINGS_AS_ERRORS}>,$<CXX_COMPILER_ID:GNU,Clang>>:-Werror>)
endfunction()
