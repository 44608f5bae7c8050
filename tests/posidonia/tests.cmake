# Regression guard of the Posidonia flume (examples/posidonia_flume, docs/posidonia.md): one real Posidonia plant as
# a porous row of leaves (--blade drag, the default) at h/dp = 10, plants only, 7 s simulated (the full waves reach
# the plant after about 3.5 s; two of them are analysed). It fails if the run blows up (exit 3) or the plant does not
# move with the water (exit 4, --check): its tip excursion must be within a factor 2 of that of the water beside it
# (a broken coupling leaves the plant still, a plant pushed harder than the flow outruns the water), its mean lean
# within 0.3 of its length and its tip never a quarter of its length below upright (the full-width rod blade, the
# failing model, leans 0.31 l and dips 0.58 l by 10 s at h/dp = 20).
if(TARGET posidonia_flume)
  add_test(NAME posidonia.drag_plant_guard
           COMMAND posidonia_flume --resolution 10 --end-time 7 --runs plants --snapshots 0 --check on
                   --output ${CMAKE_CURRENT_BINARY_DIR}/posidonia_drag_guard)
  set_tests_properties(posidonia.drag_plant_guard PROPERTIES LABELS "regression" TIMEOUT 180
                       ENVIRONMENT "OMP_NUM_THREADS=1;OMP_WAIT_POLICY=passive")
endif()

# The refined flume's flow map (posidonia_flume --flow-map-from, examples/posidonia_flume/flow_map.py,
# docs/variable-resolution.md session 34): a refined run with paired statuses at h/dp = 10 (the box at dp / 2), 2.5 s,
# the map averaged from 1.2 s; the check reads it back and asks that the active mass the status changes made and the
# mass account handed back cancel over the map to within 1e-6 of the status changes' summed magnitude (measured
# 2.5e-10 in float; with --mass-account off the net is 1.2e-5 of it, so the check fails). About 30 s on one thread.
# The same run writes the map over windows of 0.5 s (--flow-map-window, session 38); the second check asks that the
# windows add up to the whole-record map (fields weighted by samples, sources by tracked time) within 1e-6 of each
# field's largest magnitude: the CSV's 9 significant digits allow about 1e-8 (measured 7.4e-9); a window lost or
# counted twice gives a difference of order 1.
if(TARGET posidonia_flume)
  set(SPHFSI_FLOW_MAP_DIR ${CMAKE_CURRENT_BINARY_DIR}/posidonia_flow_map)
  add_test(NAME posidonia.flow_map_run
           COMMAND posidonia_flume --resolution 10 --refine on --paired-statuses on --refine-margin 0.15
                   --refine-top 0.16 --end-time 2.5 --flow-map-from 1.2 --flow-map-window 0.5 --runs plants
                   --snapshots 0 --output ${SPHFSI_FLOW_MAP_DIR})
  set_tests_properties(posidonia.flow_map_run PROPERTIES LABELS "regression" TIMEOUT 300 FIXTURES_SETUP
                       sphfsi_flow_map ENVIRONMENT "OMP_NUM_THREADS=1;OMP_WAIT_POLICY=passive")
  if(NOT Python3_Interpreter_FOUND)
    find_package(Python3 COMPONENTS Interpreter QUIET)
  endif()
  if(Python3_Interpreter_FOUND)
    add_test(NAME posidonia.flow_map_balance
             COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/examples/posidonia_flume/flow_map.py
                     ${SPHFSI_FLOW_MAP_DIR} --box 1.06,1.34,0.16 --check-balance 1e-6)
    set_tests_properties(posidonia.flow_map_balance PROPERTIES LABELS "regression" FIXTURES_REQUIRED sphfsi_flow_map)
    add_test(NAME posidonia.flow_map_windows
             COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/examples/posidonia_flume/flow_map.py
                     ${SPHFSI_FLOW_MAP_DIR} --check-windows 1e-6)
    set_tests_properties(posidonia.flow_map_windows PROPERTIES LABELS "regression" FIXTURES_REQUIRED sphfsi_flow_map)
  endif()
endif()
