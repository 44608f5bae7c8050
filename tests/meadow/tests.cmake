# Regression guards of the real-blade meadow (examples/meadow_decay, scenes/meadow.hpp): a 0.25 m meadow of 6 rod
# blades 0.5 m from the paddle in the Luhar et al. (2017) flume at the default resolution, 2 s simulated (the ramp's
# first waves pass the meadow), about 5 s each on one thread. Both fail if the run blows up or a blade falls over (tip
# below half its length: with the paper's repulsion strength k = 0.01 the blades fell over within 0.4 s).
#   meadow.short_meadow_guard       the repulsive coupling (--coupling repulsive): also fails if a fluid particle
#                                   crosses a blade
#   meadow.short_drag_meadow_guard  the porous Morison-drag coupling, the example's default (coupling/blade_drag.hpp):
#                                   the fluid passes through the blades by design
if(TARGET meadow_decay)
  add_test(NAME meadow.short_meadow_guard
           COMMAND meadow_decay --blades 6 --meadow-length 0.25 --meadow-start 0.5 --end-time 2 --runs meadow
                   --coupling repulsive --check on
                   --output ${CMAKE_CURRENT_BINARY_DIR}/meadow_guard)
  add_test(NAME meadow.short_drag_meadow_guard
           COMMAND meadow_decay --blades 6 --meadow-length 0.25 --meadow-start 0.5 --end-time 2 --runs meadow
                   --coupling drag --check on
                   --output ${CMAKE_CURRENT_BINARY_DIR}/meadow_drag_guard)
  set_tests_properties(meadow.short_meadow_guard meadow.short_drag_meadow_guard PROPERTIES LABELS "regression"
                       TIMEOUT 120 ENVIRONMENT "OMP_NUM_THREADS=1;OMP_WAIT_POLICY=passive")
endif()
