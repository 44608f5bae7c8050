# Regression runs of the examples at coarse resolution. Each example exits non-zero when its validation fails.
if(TARGET dam_break)
  # Martin & Moyce surge front at a/dp = 20 (1.6 s on 2 cores): the example's own 5 % criterion after aligning the
  # time origin (3.3 % measured at this resolution, 4.0 % at the default a/dp = 40; see docs/dam_break.md).
  add_test(NAME regression.dam_break_coarse
           COMMAND dam_break --resolution 20 --snapshots 2 --output ${CMAKE_CURRENT_BINARY_DIR}/regression/dam_break)
  set_tests_properties(regression.dam_break_coarse PROPERTIES PASS_REGULAR_EXPRESSION "PASS: aligned surge front")
endif()
