#!/usr/bin/env bash
# The test suite (which runs every shipped config) again, built with AddressSanitizer and
# UndefinedBehaviorSanitizer in build-asan/ (-O1, PLAF_SANITIZE=ON), when the compiler supports
# them. Any sanitizer report fails the run: each process writes its report to
# build-asan/sanitizer-logs/ (log_path), reports use exit codes of their own (86 ASan, 87 UBSan,
# so that a test expecting exit 1 cannot pass on one), and the folder must stay empty.
# The package test is left out: its consumer links the installed libraries without the sanitizer
# runtimes. Measured on the project's 2-core machine: build 18 min alone (24 min beside another
# build), suite 90 min beside another build. scripts/test.sh runs the cheaper part that fits CI:
# scripts/sanitize_configs.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/sanitizers_available.sh sanitize || exit 0
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_FLAGS=-O1 -DPLAF_SANITIZE=ON
cmake --build build-asan -j2 --target plaf plaf_tests
logs=$PWD/build-asan/sanitizer-logs
rm -rf "$logs"
mkdir -p "$logs"
status=0
ASAN_OPTIONS="detect_leaks=1:exitcode=86:log_path=$logs/asan" \
LSAN_OPTIONS="suppressions=$PWD/tests/sanitizer/lsan.supp:print_suppressions=0" \
UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:exitcode=87:log_path=$logs/ubsan" \
  ctest --test-dir build-asan --output-on-failure -j2 -E '^package:' || status=$?
if [ -n "$(ls -A "$logs")" ]; then
  echo "sanitize: sanitizer reports in $logs:" >&2
  head -n 40 "$logs"/* >&2
  exit 1
fi
exit "$status"
