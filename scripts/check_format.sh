#!/usr/bin/env bash
# Checks that every C++ source in git is formatted as .clang-format says (clang-format 14, Debian's
# clang-format-14): prints each file that is not, with the first differences, and fails. To format
# the tree: git ls-files '*.cpp' '*.hpp' '*.h' | xargs clang-format-14 -i
set -euo pipefail
cd "$(dirname "$0")/.."
fmt=$(command -v clang-format-14 || command -v clang-format || true)
if [ -z "$fmt" ]; then
  echo "check_format: clang-format-14 not found (scripts/install-deps.sh installs it)" >&2
  exit 1
fi
bad=()
while IFS= read -r f; do
  if ! "$fmt" --dry-run --Werror "$f" > /dev/null 2>&1; then bad+=("$f"); fi
done < <(git ls-files '*.cpp' '*.hpp' '*.h')
if [ ${#bad[@]} -gt 0 ]; then
  echo "check_format: ${#bad[@]} file(s) not formatted as .clang-format says:" >&2
  for f in "${bad[@]}"; do
    echo "  $f" >&2
    diff -u "$f" <("$fmt" "$f") | sed -n '3,12p' | sed 's/^/    /' >&2 || true
  done
  echo "format them: git ls-files '*.cpp' '*.hpp' '*.h' | xargs $fmt -i" >&2
  exit 1
fi
echo "check_format: $(git ls-files '*.cpp' '*.hpp' '*.h' | wc -l) files formatted"
