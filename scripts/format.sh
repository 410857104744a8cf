#!/usr/bin/env bash
# Formats polydg's C++ sources with .clang-format (clang-format 14, Debian's clang-format).
# Usage: scripts/format.sh          format every tracked .h and .cpp file in place
#        scripts/format.sh --check  change nothing; list the files that need formatting and exit 1
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang-format >/dev/null || { echo "format: clang-format is missing (apt-get install clang-format)" >&2; exit 2; }
mapfile -t files < <(git ls-files '*.h' '*.cpp' 2>/dev/null || find . -name '*.h' -o -name '*.cpp')
if [[ "${1:-}" == "--check" ]]; then
  # Batches of files on both cores: one clang-format per file spent most of its time starting.
  status=0
  out=$(printf '%s\0' "${files[@]}" | xargs -0 -n 64 -P 2 clang-format --dry-run -Werror 2>&1 >/dev/null) || status=$?
  mapfile -t bad < <(grep -oE '^[^:]+\.(h|cpp):[0-9]+:[0-9]+: error' <<<"$out" | cut -d: -f1 | sort -u)
  if ((status != 0 && ${#bad[@]} == 0)); then
    echo "format: clang-format failed: $out" >&2
    exit 2
  fi
  if ((${#bad[@]})); then
    echo "format: ${#bad[@]} file(s) differ from .clang-format: ${bad[*]}; run scripts/format.sh" >&2
    exit 1
  fi
  echo "format: ${#files[@]} files formatted"
else
  clang-format -i "${files[@]}"
fi
