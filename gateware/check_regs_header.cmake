# CTest rtl.regs_header: gateware/rtl/soc/spigpu_regs.vh must be what `gpubridge regs --verilog`
# prints today (the register table in protocol/src/registers.cpp is the one source).
# cmake -DGPUBRIDGE=<gpubridge> -DHEADER=<spigpu_regs.vh> -P check_regs_header.cmake
execute_process(COMMAND ${GPUBRIDGE} regs --verilog OUTPUT_VARIABLE generated RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "gpubridge regs --verilog failed (exit ${rc})")
endif()
file(READ ${HEADER} committed)
if(NOT generated STREQUAL committed)
  message(FATAL_ERROR "${HEADER} differs from the register table: regenerate it with\n"
                      "  build/tools/gpubridge regs --verilog > gateware/rtl/soc/spigpu_regs.vh\n"
                      "and rerun the gateware tests (ctest -L rtl)")
endif()
message(STATUS "spigpu_regs.vh matches the register table")
