#!/usr/bin/env bash
# One command: install what is missing, build everything (warnings are errors) and run every
# test through ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPLAF_WERROR=ON
cmake --build build -j2
ctest --test-dir build --output-on-failure -j2
