# sac_target_warnings(<target>): the project's warning set, PRIVATE to <target>
# (never exported to consumers). SAC_WARNINGS_AS_ERRORS adds -Werror.
function(sac_target_warnings target)
  if(MSVC)
    set(flags /W4 /permissive-)
    set(werror /WX)
  else()
    set(flags -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Woverloaded-virtual
              -Wcast-align -Wformat=2 -Wimplicit-fallthrough)
    set(werror -Werror)
  endif()
  if(SAC_WARNINGS_AS_ERRORS)
    list(APPEND flags ${werror})
  endif()
  target_compile_options(${target} PRIVATE ${flags})
endfunction()
