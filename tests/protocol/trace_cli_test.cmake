# End-to-end check of `gpubridge trace convert/dump` on real files:
#   cmake -DGPUBRIDGE=<exe> -DINPUT=<text trace> -DWORK=<dir> -P trace_cli_test.cmake
# text -> binary -> text -> binary must give identical binary files; a bad trace must fail with
# exit code 1 and a FILE:LINE:COL message.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

function(run expect_rc)
  execute_process(COMMAND ${GPUBRIDGE} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL expect_rc)
    message(FATAL_ERROR "gpubridge ${ARGN}: exit ${rc}, expected ${expect_rc}\n${out}\n${err}")
  endif()
  set(last_out "${out}" PARENT_SCOPE)
  set(last_err "${err}" PARENT_SCOPE)
endfunction()

run(0 trace convert ${INPUT} ${WORK}/a.gbt)
run(0 trace convert ${WORK}/a.gbt ${WORK}/b.trace)
run(0 trace convert ${WORK}/b.trace ${WORK}/b.gbt)
run(0 trace convert ${WORK}/b.gbt ${WORK}/c.txt)
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/a.gbt ${WORK}/b.gbt RESULT_VARIABLE diff_bin)
if(NOT diff_bin EQUAL 0)
  message(FATAL_ERROR "binary traces differ after text round trip")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/b.trace ${WORK}/c.txt RESULT_VARIABLE diff_txt)
if(NOT diff_txt EQUAL 0)
  message(FATAL_ERROR "canonical text changed on a second round trip")
endif()

run(0 --json trace dump ${WORK}/a.gbt)
string(JSON nframes GET "${last_out}" counts frames)
if(nframes LESS 1)
  message(FATAL_ERROR "dump --json reports no frames:\n${last_out}")
endif()

file(WRITE ${WORK}/bad.trace "CLEAR\nVERTEX X=100.3\n")
run(1 trace convert ${WORK}/bad.trace ${WORK}/bad.gbt)
if(NOT last_err MATCHES "bad.trace:2:8: X=100.3 is not a multiple of 1/16")
  message(FATAL_ERROR "unexpected error text: ${last_err}")
endif()
run(2 trace convert ${INPUT} ${WORK}/out.unknown)
