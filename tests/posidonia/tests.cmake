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
