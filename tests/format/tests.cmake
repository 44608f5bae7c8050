# clang-format check (issue 7, CI hardening), label `format`: every tracked .hpp/.cpp under include/, examples/,
# tests/ and benchmarks/ must be unchanged by `clang-format --dry-run --Werror` with the top-level .clang-format
# (written for clang-format 14, Debian 12). Paths in tests/format/exclude.txt are skipped. Without clang-format
# the test is SKIPPED (exit 77), visibly.
find_program(SPHFSI_CLANG_FORMAT NAMES clang-format clang-format-14 DOC "clang-format for the format.check test")
add_test(NAME format.check
         COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/check_format.sh "${SPHFSI_CLANG_FORMAT}" ${PROJECT_SOURCE_DIR})
set_tests_properties(format.check PROPERTIES LABELS format SKIP_RETURN_CODE 77 TIMEOUT 300)
