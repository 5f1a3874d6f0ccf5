# Makes one output that several test programs read (a recording, a run),
# once per build: `pvbench ARGS --out OUT`.  OUT.key beside the folder
# holds what made it (the pvbench binary's time stamp and size, the arguments, the
# contents of INPUTS); when the key still holds, the output is kept as it
# is, so running a few tests again does not make it again.  Written into a
# private folder, then renamed into place.
#   cmake -DPVBENCH=... -DOUT=... -DARGS="a;b;c" [-DINPUTS="f1;f2"] -P shared_output.cmake
foreach(v PVBENCH OUT ARGS)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "shared_output.cmake: -D${v}=... is required")
  endif()
endforeach()

file(TIMESTAMP "${PVBENCH}" stamp "%Y-%m-%dT%H:%M:%S" UTC)
file(SIZE "${PVBENCH}" size)
set(key "pvbench ${stamp} ${size}\nargs ${ARGS}\n")
foreach(input IN LISTS INPUTS)
  file(SHA256 "${input}" sha)
  string(APPEND key "${input} ${sha}\n")
endforeach()

set(key_file "${OUT}.key")
if(EXISTS "${key_file}")
  file(READ "${key_file}" old_key)
  if(old_key STREQUAL key)
    message(STATUS "${OUT}: up to date")
    return()
  endif()
endif()

file(REMOVE_RECURSE "${OUT}" "${OUT}.tmp" "${key_file}")
get_filename_component(parent "${OUT}" DIRECTORY)
file(MAKE_DIRECTORY "${parent}")
string(REPLACE ";" " " shown "${ARGS}")
message(STATUS "pvbench ${shown} --out ${OUT}")
execute_process(COMMAND "${PVBENCH}" ${ARGS} --out "${OUT}.tmp" RESULT_VARIABLE rc
                OUTPUT_VARIABLE log ERROR_VARIABLE log)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pvbench ${shown} failed (${rc}):\n${log}")
endif()
file(RENAME "${OUT}.tmp" "${OUT}")
file(WRITE "${key_file}" "${key}")
