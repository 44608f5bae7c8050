# Compile-fail tests (included by tests/CMakeLists.txt): what must NOT compile.
#
# Each source holds a complete user policy (kernel or EOS) plugged into a ParticleSystem; with SPHFSI_COMPILE_FAIL
# defined one required member is taken away. For each source two EXCLUDE_FROM_ALL object targets are made and two
# CTest tests build them with `cmake --build`:
#   compile_fail.<name>          builds the broken variant; passes only if the compiler output names the concept
#                                AND the missing requirement (a failure for any other reason does not count)
#   compile_fail.<name>.control  builds the complete variant; must succeed, so the file itself is sound and the
#                                failure above comes from the missing member alone
# The regular expressions accept GCC's ("required for the satisfaction of 'C<...>' ... the required expression
# 'e' is invalid") and Clang's ("does not satisfy 'C'" ... "because 'e' would be invalid") wording.
set(_cf_not_satisfied "(satisfaction of|does not satisfy) [^ ]*")
set(SPHFSI_COMPILE_FAIL_CASES
    "kernel_missing_derivative|${_cf_not_satisfied}SmoothingKernel.*derivative\\(r, h\\)[^ ]* (is|would be) invalid"
    "eos_missing_sound_speed|${_cf_not_satisfied}EquationOfState.*sound_speed\\(rho\\)[^ ]* (is|would be) invalid"
    "kernel_with_virtual_function|${_cf_not_satisfied}SmoothingKernel.*is_trivially_copyable_v.*evaluated to")

foreach(_cf_case ${SPHFSI_COMPILE_FAIL_CASES})
  string(FIND "${_cf_case}" "|" _cf_bar)
  string(SUBSTRING "${_cf_case}" 0 ${_cf_bar} _cf_name)
  math(EXPR _cf_regex_begin "${_cf_bar} + 1")
  string(SUBSTRING "${_cf_case}" ${_cf_regex_begin} -1 _cf_regex)

  foreach(_cf_variant broken control)
    set(_cf_target sphfsi_compile_fail_${_cf_name}_${_cf_variant})
    add_library(${_cf_target} OBJECT EXCLUDE_FROM_ALL ${CMAKE_CURRENT_LIST_DIR}/${_cf_name}.cpp)
    target_link_libraries(${_cf_target} PRIVATE sphfsi::sphfsi)
    if(_cf_variant STREQUAL "broken")
      target_compile_definitions(${_cf_target} PRIVATE SPHFSI_COMPILE_FAIL)
      set(_cf_test compile_fail.${_cf_name})
    else()
      set(_cf_test compile_fail.${_cf_name}.control)
    endif()
    add_test(NAME ${_cf_test}
             COMMAND ${CMAKE_COMMAND} --build ${CMAKE_BINARY_DIR} --target ${_cf_target} --config $<CONFIG>)
    # One build of this tree at a time: concurrent `cmake --build` calls would race on its bookkeeping.
    set_tests_properties(${_cf_test} PROPERTIES RESOURCE_LOCK sphfsi_build_tree LABELS compile_fail TIMEOUT 300)
    if(_cf_variant STREQUAL "broken")
      set_tests_properties(${_cf_test} PROPERTIES PASS_REGULAR_EXPRESSION "${_cf_regex}")
    endif()
  endforeach()
endforeach()
