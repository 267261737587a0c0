#!/usr/bin/env bash
# Format and lint checks, run by `bash tools/bootstrap.sh test` (so by CI).
#   bash tools/lint.sh            # check: fails on any file clang-format would change
#                                 # or any clang-tidy finding (.clang-tidy's checks)
#   bash tools/lint.sh --fix      # format the tree in place (then commit)
# Needs clang-format and clang-tidy (Debian 12: version 14; bootstrap.sh installs
# them) and build/release/compile_commands.json (a configured release build).
set -euo pipefail
cd "$(dirname "$0")/.."

# A missing tool must fail the check, not pass it: clang-tidy's output is
# filtered below, so a missing one would look like a clean run.
for tool in clang-format clang-tidy; do
  command -v "$tool" >/dev/null || { echo "lint: $tool not found (bash tools/bootstrap.sh test installs it)" >&2; exit 2; }
done

mapfile -t sources < <(git ls-files '*.cpp' '*.hpp' '*.h' | grep -v '^build/')
if [ "${1:-}" = "--fix" ]; then
  clang-format -i "${sources[@]}"
  echo "lint: formatted ${#sources[@]} files"
  exit 0
fi

status=0
if ! clang-format --dry-run --Werror "${sources[@]}" 2>/tmp/hfmpm-format.$$; then
  grep -E '^[^ ].*(error|warning):' /tmp/hfmpm-format.$$ | cut -d: -f1 | sort -u | sed 's/^/lint: not formatted: /'
  echo "lint: run 'bash tools/lint.sh --fix' to format" >&2
  status=1
fi
rm -f /tmp/hfmpm-format.$$

# clang-tidy on the project's own translation units (tests excluded: gtest's
# macros trip bugprone checks by design), one per core. The compile commands
# are GCC's: clang is told to ignore GCC-only warning options and -Werror (the
# compiler's warnings are GCC's to judge; clang-tidy judges its checks).
db=build/release/compile_commands.json
[ -f "$db" ] || { echo "lint: $db missing; configure first (cmake --preset release)" >&2; exit 2; }
mapfile -t units < <(/usr/bin/python3 -c "
import json, os
root = os.getcwd() + '/'
for c in json.load(open('$db')):
    f = c['file']
    if f.startswith(root) and '/tests/' not in f and '/build/' not in f:
        print(f[len(root):])")
findings=$(printf '%s\n' "${units[@]}" | xargs -P "$(nproc)" -n 1 \
             clang-tidy -p build/release --quiet --warnings-as-errors='*' \
               --extra-arg=-Wno-unknown-warning-option --extra-arg=-Wno-error 2>/dev/null || true)
if grep -E 'warning:|error:' <<<"$findings"; then
  status=1
fi
[ $status -eq 0 ] && echo "lint: ${#sources[@]} files formatted, ${#units[@]} units clean under clang-tidy"
exit $status
