# Smoke tests of examples/blade_in_current at a coarse resolution (l / dp = 8, 2 towing lengths, a few seconds each on
# one thread): both sweeps run to their summaries, and the force-law sweep's inclined.csv reads back as --force-law.
# They fail on a crash, a blow-up of the rigid reference, or a summary row that does not match its header (session 22:
# a row with two more values than the header's columns stopped the example at the end of a 5-minute sweep). No physics
# is checked here: the effective lengths and force laws are docs/thin-blades.md's full-resolution runs. The Cauchy
# sweep uses the porous rod (--coupling drag): at l / dp = 8 the resolved flexible blade leaves the domain through the
# bed (Ca = 100 and 1000, a contact gap of 2 dp = l / 4), which the summary would only report as NaN.
if(TARGET blade_in_current)
  add_test(NAME blade_in_current.force_law_sweep
           COMMAND blade_in_current --depth 5 --resolution 8 --tow-lengths 2 --average-from 0 --inclinations 0,45
                   --output ${CMAKE_CURRENT_BINARY_DIR}/blade_force_law)
  add_test(NAME blade_in_current.cauchy_sweep
           COMMAND blade_in_current --depth 5 --resolution 8 --tow-lengths 2 --average-from 0 --cauchy 0,100
                   --coupling drag
                   --force-law ${CMAKE_CURRENT_BINARY_DIR}/blade_force_law/inclined.csv
                   --output ${CMAKE_CURRENT_BINARY_DIR}/blade_cauchy)
  # The 3D strip (a ribbon, --three-d): rigid and flexible, 0.15 s each at l / dp = 6 with the background pressure
  # and the visibility criterion in 3D; fails on a crash or a blow-up.
  add_test(NAME blade_in_current.ribbon_3d
           COMMAND blade_in_current --three-d on --resolution 6 --depth 2 --channel-width 3 --cauchy 0,100
                   --end-time 0.15 --background-pressure 4 --contact-gap 0.5
                   --output ${CMAKE_CURRENT_BINARY_DIR}/blade_ribbon_3d)
  # The double blade clamped at its middle (--clamp-middle, a blade on a free-slip plane) on extrapolated walls
  # (--walls extrapolated): rigid and flexible, 0.15 s at l / dp = 8 per half; fails on a crash or a blow-up.
  add_test(NAME blade_in_current.double_blade_extrapolated_walls
           COMMAND blade_in_current --resolution 16 --length 0.1 --depth 3 --mount-height 1 --clamp-middle on
                   --walls extrapolated --cauchy 0,100 --end-time 0.15 --background-pressure 4 --contact-gap 0.5
                   --output ${CMAKE_CURRENT_BINARY_DIR}/blade_double_extrapolated)
  # The force-law sweep of 3D strips (session 33) on extrapolated walls, 1 towing length at l / dp = 6 (about 30 s on one
  # thread), and its inclined.csv read back by --static-only (the static blade under the measured law, no run).
  add_test(NAME blade_in_current.force_law_3d
           COMMAND blade_in_current --three-d on --resolution 6 --depth 2 --channel-width 3 --inclinations 0,45
                   --tow-lengths 1 --average-from 0 --background-pressure 4 --walls extrapolated
                   --output ${CMAKE_CURRENT_BINARY_DIR}/blade_force_law_3d)
  add_test(NAME blade_in_current.static_only
           COMMAND blade_in_current --static-only on --cauchy 10,100
                   --force-law ${CMAKE_CURRENT_BINARY_DIR}/blade_force_law_3d/inclined.csv)
  set_tests_properties(blade_in_current.force_law_3d PROPERTIES FIXTURES_SETUP blade_force_law_3d)
  set_tests_properties(blade_in_current.static_only PROPERTIES FIXTURES_REQUIRED blade_force_law_3d)
  set_tests_properties(blade_in_current.force_law_3d blade_in_current.static_only PROPERTIES LABELS "regression"
                       TIMEOUT 120 ENVIRONMENT "OMP_NUM_THREADS=1;OMP_WAIT_POLICY=passive")
  set_tests_properties(blade_in_current.double_blade_extrapolated_walls PROPERTIES LABELS "regression" TIMEOUT 120
                       ENVIRONMENT "OMP_NUM_THREADS=1;OMP_WAIT_POLICY=passive")
  set_tests_properties(blade_in_current.ribbon_3d PROPERTIES LABELS "regression" TIMEOUT 120
                       ENVIRONMENT "OMP_NUM_THREADS=1;OMP_WAIT_POLICY=passive")
  set_tests_properties(blade_in_current.force_law_sweep PROPERTIES FIXTURES_SETUP blade_force_law)
  set_tests_properties(blade_in_current.cauchy_sweep PROPERTIES FIXTURES_REQUIRED blade_force_law)
  set_tests_properties(blade_in_current.force_law_sweep blade_in_current.cauchy_sweep PROPERTIES LABELS "regression"
                       TIMEOUT 120 ENVIRONMENT "OMP_NUM_THREADS=1;OMP_WAIT_POLICY=passive")
endif()
