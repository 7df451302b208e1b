#!/usr/bin/env bash
# Formats every C++ file of the three packages with clang-format and the top-level .clang-format.
#   scripts/format.sh           rewrite the files in place
#   scripts/format.sh --check   list the files that are not formatted; exit 1 if any
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(git ls-files '*.cpp' '*.h')
if [[ "${1:-}" == "--check" ]]; then
  clang-format --dry-run --Werror "${files[@]}" 2>&1 | grep -o '^[^:]*\.\(cpp\|h\)' | sort -u || true
  clang-format --dry-run --Werror "${files[@]}" >/dev/null 2>&1
else
  clang-format -i "${files[@]}"
fi
