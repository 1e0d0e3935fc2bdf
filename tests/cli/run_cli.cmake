# Runs the radiosity CLI once and checks its exit code and output (ctest: cmake -P this file).
#   -DEXE=<path>              the radiosity executable
#   -DARGS=<a|b|c>            its arguments, separated by '|'
#   -DCODE=<n>                the exit code it must return
#   -DSTDOUT=<regex>          optional: stdout must match
#   -DSTDERR=<regex>          optional: stderr must match
#   -DONE_ERROR_LINE=ON       optional: stderr has exactly one line "radiosity: error: ...",
#                             shorter than 200 characters
#   -DSTDOUT_JSON=ON          optional: stdout is one JSON object (parsed by string(JSON))
cmake_minimum_required(VERSION 3.20)
string(REPLACE "|" ";" args "${ARGS}")
# The test definitions send a regex's ';' as <semicolon> (a ';' would split the argument).
foreach(stream STDOUT STDERR)
  if(DEFINED ${stream})
    string(REPLACE "<semicolon>" ";" ${stream} "${${stream}}")
  endif()
endforeach()
execute_process(COMMAND ${EXE} ${args} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(what "radiosity ${args}\n--- stdout:\n${out}--- stderr:\n${err}")
if(NOT code STREQUAL "${CODE}")
  message(FATAL_ERROR "exit code ${code}, expected ${CODE}: ${what}")
endif()
if(DEFINED STDOUT AND NOT out MATCHES "${STDOUT}")
  message(FATAL_ERROR "stdout does not match '${STDOUT}': ${what}")
endif()
if(DEFINED STDERR AND NOT err MATCHES "${STDERR}")
  message(FATAL_ERROR "stderr does not match '${STDERR}': ${what}")
endif()
if(STDOUT_JSON)
  string(JSON type ERROR_VARIABLE json_error TYPE "${out}")
  if(json_error OR NOT type STREQUAL "OBJECT")
    message(FATAL_ERROR "stdout is not a JSON object (${json_error}): ${what}")
  endif()
endif()
if(ONE_ERROR_LINE)
  string(REGEX MATCHALL "radiosity: error: [^\n]*" lines "${err}")
  list(LENGTH lines n)
  if(NOT n EQUAL 1)
    message(FATAL_ERROR "${n} error lines, expected 1: ${what}")
  endif()
  string(LENGTH "${lines}" length)
  if(length GREATER_EQUAL 200)
    message(FATAL_ERROR "error line of ${length} characters: ${what}")
  endif()
endif()
