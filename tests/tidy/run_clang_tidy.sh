#!/bin/sh
# Runs clang-tidy (the checks of the top-level .clang-tidy, every finding an error) on one translation unit.
# usage: run_clang_tidy.sh <clang-tidy> <build dir with compile_commands.json> <source file>
# Exit 77 (CTest: skipped) when clang-tidy or the compile database is missing.
tidy="$1" build_dir="$2" source="$3"
if [ -z "$tidy" ] || [ ! -x "$tidy" ]; then
  echo "SKIPPED: clang-tidy not found (Debian: apt-get install clang-tidy)"
  exit 77
fi
if [ ! -f "$build_dir/compile_commands.json" ]; then
  echo "SKIPPED: no $build_dir/compile_commands.json; configure with -DCMAKE_EXPORT_COMPILE_COMMANDS=ON"
  exit 77
fi
"$tidy" --quiet -p "$build_dir" "$source" || {
  echo "FAILED: clang-tidy found problems in $source or in the sphfsi headers it includes"
  exit 1
}
echo "clang-tidy: no findings in $source and the sphfsi headers it includes"
