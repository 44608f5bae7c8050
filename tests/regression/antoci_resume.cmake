# A coupled fluid-structure run stopped and resumed from its checkpoint gives the same gate-tip record, bit for bit,
# as the uninterrupted run (issue 7): cmake -DEXE=<antoci_gate> -DOUT=<folder> -P antoci_resume.cmake
set(common --resolution 60 --snapshot-interval 1)
file(REMOVE_RECURSE ${OUT})
execute_process(COMMAND ${EXE} ${common} --end-time 0.02 --output ${OUT}/whole RESULT_VARIABLE r1 OUTPUT_QUIET)
execute_process(COMMAND ${EXE} ${common} --end-time 0.012 --checkpoint-interval 0.01 --output ${OUT}/parts
                RESULT_VARIABLE r2 OUTPUT_QUIET)
execute_process(COMMAND ${EXE} ${common} --end-time 0.02 --resume yes --output ${OUT}/parts RESULT_VARIABLE r3
                OUTPUT_VARIABLE log)
if(NOT log MATCHES "resumed from .* at t = 0.0100 s")
  message(FATAL_ERROR "the second part did not resume from the checkpoint at t = 0.01 s:\n${log}")
endif()
file(READ ${OUT}/whole/gate_tip.csv whole)
file(READ ${OUT}/parts/gate_tip.csv parts)
if(NOT whole STREQUAL parts)
  message(FATAL_ERROR "gate_tip.csv of the resumed run differs from the uninterrupted run")
endif()
string(LENGTH "${whole}" n)
message(STATUS "resumed run identical to the uninterrupted one (${n} bytes of gate-tip record)")
