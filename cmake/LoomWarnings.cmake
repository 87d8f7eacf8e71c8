# Warnings for loom's own targets only (third-party headers are SYSTEM includes).
#
# LOOM_SANITIZE (and LOOM_FUZZ, which implies it) adds ASan and UBSan. A UBSan finding aborts
# (no recovery): a report that only prints would pass every test. EIGEN_MALLOC_ALREADY_ALIGNED
# keeps Eigen on plain malloc under ASan, where it otherwise switches to its handmade aligned
# allocator and, through the symbols an executable exports, frees OMPL's plain allocations
# with it (docs/DESIGN-NOTES.md, "Tests and benchmarks"); every target compiled here must
# agree on it. LOOM_FUZZ also instruments loom's code for libFuzzer's coverage feedback.
function(loom_target_warnings target)
  # GCC's -Wshadow=local is spelled -Wshadow-uncaptured-local in clang (the fuzz build).
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic
                         $<IF:$<CXX_COMPILER_ID:Clang>,-Wshadow-uncaptured-local,-Wshadow=local>
                         -Wno-deprecated-declarations)
  if(LOOM_SANITIZE OR LOOM_FUZZ)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-sanitize-recover=undefined
                           -fno-omit-frame-pointer)
    target_compile_definitions(${target} PRIVATE EIGEN_MALLOC_ALREADY_ALIGNED=1)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
  if(LOOM_FUZZ)
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
endfunction()
