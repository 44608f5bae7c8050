# clang-tidy on representative translation units (issue 7, CI hardening), label `tidy`. The checks are in the
# top-level .clang-tidy; every finding is an error. Each unit pulls in most of the library's headers, and the
# HeaderFilterRegex there reports findings in include/sphfsi too:
#   examples/dam_break/main.cpp     fluid, walls, integrators, scenes, VTK/CSV output, command line
#   examples/antoci_gate/main.cpp   elastic solids, FSI coupling, sub-cycling, checkpoints
#   tests/unit/test_neighbors.cpp   cell list, kernels, particle system
# Needs the compile database (CMAKE_EXPORT_COMPILE_COMMANDS=ON, set by the test preset); without it, or without
# clang-tidy, the tests are SKIPPED (exit 77), visibly.
find_program(SPHFSI_CLANG_TIDY NAMES clang-tidy clang-tidy-14 DOC "clang-tidy for the tidy.* tests")
set(_sphfsi_tidy_units
    dam_break examples/dam_break/main.cpp
    antoci_gate examples/antoci_gate/main.cpp
    neighbors tests/unit/test_neighbors.cpp)
while(_sphfsi_tidy_units)
  list(POP_FRONT _sphfsi_tidy_units _name _file)
  if(_file MATCHES "^examples/" AND NOT TARGET ${_name})
    continue()  # examples not configured (SPHFSI_BUILD_EXAMPLES=OFF): no compile command for them
  endif()
  add_test(NAME tidy.${_name}
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/run_clang_tidy.sh "${SPHFSI_CLANG_TIDY}" ${CMAKE_BINARY_DIR}
                   ${PROJECT_SOURCE_DIR}/${_file})
  set_tests_properties(tidy.${_name} PROPERTIES LABELS tidy SKIP_RETURN_CODE 77 TIMEOUT 300)
endwhile()
unset(_sphfsi_tidy_units)
