# Runs one scenario of the suite end to end and checks its bounds:
#   pvbench run --scenario SCENARIO --out OUT --compare --sync --check
#   pvbench check --scenario SCENARIO --metrics OUT/metrics.json
# With -DFRAMES=N (the fast CI set's expect.ci_frames), the run is PE-SLAM's
# alone over N frames without map scoring (--frames N --no-map-eval): the
# bounds judge PE-SLAM's trajectory only; the baseline and the dense-map
# scores are covered by the full runs and by pvbench run's own tests.
# Fails when the run crashes or exits with anything but 0 (bounds hold) or 3
# (a bound is violated; "aborted" by route.on_loss is judged by the checker:
# only a scenario that expects a tracking loss accepts it), when a bound in
# the scenario's expect: section is violated, or when `run --check` and
# `pvbench check` disagree.  pvbench's output goes to
# OUT.stdout.log; the tail is printed on failure.
foreach(v PVBENCH SCENARIO OUT)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "run_scenario.cmake: -D${v}=... is required")
  endif()
endforeach()

file(REMOVE_RECURSE "${OUT}")
get_filename_component(parent "${OUT}" DIRECTORY)
file(MAKE_DIRECTORY "${parent}")
set(log "${OUT}.stdout.log")
set(args run --scenario "${SCENARIO}" --out "${OUT}" --sync --check)
if(FRAMES)
  list(APPEND args --frames ${FRAMES} --no-map-eval)
else()
  list(APPEND args --compare)
endif()
string(REPLACE ";" " " shown "${args}")
message(STATUS "pvbench ${shown}")
execute_process(COMMAND "${PVBENCH}" ${args} RESULT_VARIABLE rc OUTPUT_FILE "${log}" ERROR_FILE "${log}")
set(run_rc ${rc})
if(NOT rc EQUAL 0 AND NOT rc EQUAL 3)
  file(STRINGS "${log}" lines)
  list(LENGTH lines n)
  if(n GREATER 40)
    math(EXPR first "${n} - 40")
    list(SUBLIST lines ${first} 40 lines)
  endif()
  string(REPLACE ";" "\n" tail "${lines}")
  message(FATAL_ERROR "pvbench run failed (${rc}); last lines of ${log}:\n${tail}")
endif()

execute_process(COMMAND "${PVBENCH}" check --scenario "${SCENARIO}" --metrics "${OUT}/metrics.json"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
message("${out}")
if((rc EQUAL 0) AND NOT (run_rc EQUAL 0) OR (run_rc EQUAL 0) AND NOT (rc EQUAL 0))
  message(FATAL_ERROR "pvbench run --check exited ${run_rc} but pvbench check exited ${rc}")
endif()
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pvbench check: the run violates the scenario's expect: bounds (exit ${rc})")
endif()
