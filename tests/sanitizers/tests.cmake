# AddressSanitizer + UndefinedBehaviorSanitizer run of the core unit tests (issue 7, CI hardening).
# A second, coarser unit-test executable, sphfsi_unit_tests_sanitized, built at -O1 -g1 with
#   -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
# from the unit-test files that exercise the core: equations of state, neighbour search, I/O (VTK, CSV,
# checkpoints), couplings, solids, particle refinement and the robustness suite (validation, blow-ups, restart).
# Left out to keep the compile time of CI sane: the kernel tests (test_kernels.cpp: pure functions of r and h, which
# every SPH sum of the files above evaluates under the sanitizers anyway; the largest sanitized unit, 85 s of
# compilation), the wave-flume tests (test_waves.cpp, analysis on top of the same core loops) and the
# one-definition-rule pair (test_odr*.cpp, a link-time check that the normal build already performs). Catch2's main
# is the uninstrumented object of tests/CMakeLists.txt (the runner itself is not under test).
# One CTest test, label `sanitizer`; it halts at the first error. The full suite under sanitizers is the `asan`
# preset (cmake --workflow --preset asan).
option(SPHFSI_SANITIZER_TESTS "Build and run the core unit tests under ASan + UBSan (test preset: ON)" OFF)
if(NOT SPHFSI_SANITIZER_TESTS)
  return()
endif()
if(NOT CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  message(WARNING "SPHFSI_SANITIZER_TESTS needs GCC or Clang (-fsanitize=address,undefined); not built")
  return()
endif()

set(SPHFSI_SANITIZED_UNIT_SOURCES
    test_eos.cpp test_neighbors.cpp test_io.cpp test_couplings.cpp test_solids.cpp
    test_robustness.cpp test_particle_refinement.cpp)
list(TRANSFORM SPHFSI_SANITIZED_UNIT_SOURCES PREPEND ${CMAKE_CURRENT_LIST_DIR}/../unit/)
add_executable(sphfsi_unit_tests_sanitized $<TARGET_OBJECTS:sphfsi_catch_main> ${SPHFSI_SANITIZED_UNIT_SOURCES})
target_link_libraries(sphfsi_unit_tests_sanitized PRIVATE sphfsi::sphfsi Catch2::Catch2)
set(_sphfsi_sanitize -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
# -O1 -g1, as the preset: line tables, so every ASan / UBSan report names file and line for each frame, but no
# variable information. Session 36 measured full debug information (-g) here: the sanitized test_couplings.cpp compiled
# in 215 s against 102 s with -g1, and all seven units in 812 s, over half the CI's compiling. The asan preset keeps
# -g for debugging a report locally.
target_compile_options(sphfsi_unit_tests_sanitized PRIVATE ${_sphfsi_sanitize} -O1 -g1)
target_link_options(sphfsi_unit_tests_sanitized PRIVATE ${_sphfsi_sanitize})
target_compile_definitions(sphfsi_unit_tests_sanitized PRIVATE
  SPHFSI_SHARED_DATA_DIR="${SPHFSI_SHARED_DATA_DIR}"
  SPHFSI_TEST_OUTPUT_DIR="${CMAKE_CURRENT_BINARY_DIR}/output_sanitized"
  # test_neighbors.cpp: the brute-force comparisons for two of the four dimension / scalar combinations.
  SPHFSI_SANITIZED_UNIT_TESTS)
unset(_sphfsi_sanitize)

# The long physics runs are left out; under ASan + UBSan at -O1 (Eigen's small fixed-size expressions are no longer
# inlined, every index is checked) they run about 27 times slower than in a release build:
#   - the undamped oscillating-plate energy tests of both solid models (5 periods: 73 s TLSPH, 18 s ULSPH here),
#   - the free spinning-body momentum test of both solid models in 2D and 3D (9.5 s release, ~260 s here),
#   - the plate periods at H/dp = 4 of both models (ULSPH ~50 s, TLSPH 38 s here).
# The same solid loops (both models) run here in the rigid-rotation, sub-cycling, clamp, gradient-correction and
# checkpoint cases of test_solids.cpp and test_solid_checkpoint.cpp. (Several specs given to Catch are AND-ed.)
# The refined still tank (test_particle_refinement.cpp, 11 s release) is left out too; its splitting, merging, particle
# removal and checkpoint paths run here in the other refinement cases. So is the Posidonia blade in the still flume
# (test_posidonia_flume.cpp, 8 s of simulated flume, 30 CPU s at -O2); its rod, dashpot and crossing-counter code runs
# here in the coupling and rod-blade cases. The APR still tank with nested boxes (30 s release) is left out as well;
# the APR passes, fits and mass account run here in the other [apr] cases. Session 35 (the sanitized run had grown to
# 393 s of the CI's test step, 518 s alone on one core): the still column on a solid wall of the interface-pressure
# coupling (5.3 s at -O2, 225 s here; the coupling's sums run here in its two momentum cases) and the jet at a 3D
# ribbon (5.5 s, 123 s here; the ribbon's surface points and forces run here in "pushes on both faces, only in them").
set(SPHFSI_SANITIZER_EXCLUDED_CASES "~TLSPH: energy of the undamped oscillating plate*"
                                    "~ULSPH: energy of the undamped oscillating plate*"
                                    "~TLSPH: oscillating plate period*"
                                    "~Solid models conserve momentum in a free*" "~ULSPH: oscillating plate period*"
                                    "~hydrostatic tank with a refined band*" "~a real Posidonia blade stands*"
                                    "~adaptive refinement: a still tank*"
                                    "~interface pressure: a still column*" "~repulsive force on a 3D ribbon: a jet*")
add_test(NAME sanitizer.unit_tests COMMAND sphfsi_unit_tests_sanitized ${SPHFSI_SANITIZER_EXCLUDED_CASES})
set_tests_properties(sanitizer.unit_tests PROPERTIES
  LABELS sanitizer
  TIMEOUT 600
  ENVIRONMENT "ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:halt_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1;UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1;OMP_WAIT_POLICY=passive")
