# cmake -DGPUBRIDGE=path -P bench_remote_smoke.cmake
# `gpubridge bench remote` end to end on one example with few frames: every configuration ran and
# reported a frame rate, and compression made the terrain's frames smaller.
execute_process(COMMAND ${GPUBRIDGE} --json bench remote terrain --frames 6 --fps 30
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "gpubridge bench remote failed (${rc}): ${err}")
endif()
string(JSON n LENGTH "${out}" examples 0 runs)
if(NOT n EQUAL 6)
  message(FATAL_ERROR "expected 6 configurations, got ${n}: ${out}")
endif()
math(EXPR last "${n} - 1")
foreach(i RANGE ${last})
  string(JSON play GET "${out}" examples 0 runs ${i} play_fps)
  string(JSON stream GET "${out}" examples 0 runs ${i} stream_fps)
  if(NOT play GREATER 0 OR NOT stream GREATER 0)
    message(FATAL_ERROR "run ${i}: no frame rate: ${out}")
  endif()
endforeach()
string(JSON ratio GET "${out}" examples 0 compression_ratio)
if(NOT ratio GREATER 1)
  message(FATAL_ERROR "zstd did not shrink the terrain's frames: ${out}")
endif()
