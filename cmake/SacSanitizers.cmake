# SAC_SANITIZER_FLAGS: compile and link flags of the sanitizer build (ASan + UBSan).
set(SAC_SANITIZER_FLAGS -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)

# sac_enable_sanitizers(): instrument every target defined from the calling directory down.
# Sanitizers must cover all translation units alike, hence directory scope, not per target.
function(sac_enable_sanitizers)
  if(MSVC)
    message(FATAL_ERROR "SAC_SANITIZE needs GCC or Clang")
  endif()
  add_compile_options(${SAC_SANITIZER_FLAGS})
  add_link_options(${SAC_SANITIZER_FLAGS})
  message(STATUS "sac: sanitizers on: ${SAC_SANITIZER_FLAGS}")
endfunction()

# sac_enable_fuzzing(): the libFuzzer build of DYNMESH_FUZZ. Every target from the calling
# directory down gets ASan + UBSan and libFuzzer's coverage instrumentation (fuzzer-no-link),
# so the fuzzer sees the edges of the libraries, not only of the fuzz targets; the targets
# themselves link -fsanitize=fuzzer (tests/fuzz/). libFuzzer ships with clang only.
# Comparison tracing (trace-cmp) is off except where tests/fuzz/ turns it back on (the text
# readers): the differential targets decode their input into integers, so it guides nothing
# there, and its hooks in the trees' hash probes and sorts made them 2.5 times slower.
function(sac_enable_fuzzing)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "DYNMESH_FUZZ needs clang (libFuzzer), but the C++ compiler is "
                        "${CMAKE_CXX_COMPILER_ID} ${CMAKE_CXX_COMPILER_VERSION}: configure a fresh build "
                        "directory with -DCMAKE_CXX_COMPILER=clang++ (or use `bash dev.sh fuzz`)")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link -fno-sanitize-coverage=trace-cmp ${SAC_SANITIZER_FLAGS})
  add_link_options(${SAC_SANITIZER_FLAGS})
  message(STATUS "dynmesh: libFuzzer build: -fsanitize=fuzzer-no-link ${SAC_SANITIZER_FLAGS}")
endfunction()
