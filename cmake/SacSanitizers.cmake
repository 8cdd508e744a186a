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
