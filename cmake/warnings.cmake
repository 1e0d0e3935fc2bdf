# Warnings for the project's own targets; RADIOSITY_WERROR (on in CI) turns them into errors.
function(radiosity_set_warnings target)
  if(MSVC)
    target_compile_options(${target} PRIVATE /W4 $<$<BOOL:${RADIOSITY_WERROR}>:/WX>)
  else()
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow
      $<$<BOOL:${RADIOSITY_WERROR}>:-Werror>)
  endif()
endfunction()
