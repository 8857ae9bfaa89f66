#!/usr/bin/env bash
# One command: install what is missing, build everything (warnings are errors) and run every
# test through ctest; then the shipped configs under ASan+UBSan (scripts/sanitize_configs.sh,
# skipped where the compiler has no sanitizers, or with PLAF_SANITIZE_CONFIGS=0).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPLAF_WERROR=ON
cmake --build build -j2
ctest --test-dir build --output-on-failure -j2
if [ "${PLAF_SANITIZE_CONFIGS:-1}" != 0 ]; then
  bash scripts/sanitize_configs.sh
fi
