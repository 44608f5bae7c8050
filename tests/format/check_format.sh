#!/bin/sh
# Checks that every C++ source of the project is formatted by clang-format with the top-level .clang-format.
# usage: check_format.sh <clang-format> <source dir>
# Files: the tracked *.hpp and *.cpp under include/, examples/, tests/ and benchmarks/ (`git ls-files`; without git
# or outside a work tree, every such file found there), minus the paths listed in tests/format/exclude.txt.
# Exit 77 (CTest: skipped) when clang-format is missing. Fix a failure with:  clang-format -i <file>
format="$1" source_dir="$2"
if [ -z "$format" ] || [ ! -x "$format" ]; then
  echo "SKIPPED: clang-format not found (Debian: apt-get install clang-format)"
  exit 77
fi
cd "$source_dir" || exit 1
list=$(mktemp) || exit 1
trap 'rm -f "$list"' EXIT
if command -v git >/dev/null 2>&1 && git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  git ls-files -- 'include/*.hpp' 'include/*.cpp' 'examples/*.hpp' 'examples/*.cpp' 'tests/*.hpp' 'tests/*.cpp' \
    'benchmarks/*.hpp' 'benchmarks/*.cpp' > "$list"
else
  find include examples tests benchmarks -type f \( -name '*.hpp' -o -name '*.cpp' \) | sort > "$list"
fi
# Exclusions: one path per line, relative to the source dir; '#' starts a comment.
exclude="tests/format/exclude.txt"
if [ -f "$exclude" ]; then
  sed -e 's/#.*//' -e 's/[[:space:]]*$//' -e '/^$/d' "$exclude" | grep -v -x -F -f - "$list" > "$list.kept"
  mv "$list.kept" "$list"
fi
count=$(wc -l < "$list")
if [ "$count" -eq 0 ]; then
  echo "FAILED: no C++ files found under $source_dir"
  exit 1
fi
"$format" --version
# -n: --dry-run; --Werror: a file that would change is an error. xargs keeps the command line short.
if xargs "$format" --dry-run --Werror < "$list"; then
  echo "clang-format: $count files checked, all formatted"
else
  echo "FAILED: clang-format would change the files above; run: clang-format -i <file>"
  exit 1
fi
