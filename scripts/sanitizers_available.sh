#!/usr/bin/env bash
# Exit 0 when ${CXX:-c++} links a program with -fsanitize=address,undefined, else say so on
# stderr (naming the caller, $1) and exit 1. Used by scripts/sanitize.sh and sanitize_configs.sh.
probe=$(mktemp)
trap 'rm -f "$probe"' EXIT
if echo 'int main() { return 0; }' | "${CXX:-c++}" -x c++ -fsanitize=address,undefined - -o "$probe" 2>/dev/null; then
  exit 0
fi
echo "${1:-sanitize}: ${CXX:-c++} does not build with -fsanitize=address,undefined; skipped" >&2
exit 1
