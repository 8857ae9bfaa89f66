#!/usr/bin/env bash
# One command on a fresh Debian 12 machine: install what is missing, build (Release) and run the
# default job (configs/naca0012_hybrid.yaml: the NACA 0012 hybrid mesh, on a section plaf generates,
# so it needs no published data) into out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j2 --target plaf  # the tool only; scripts/test.sh builds the tests
./build/apps/plaf run configs/naca0012_hybrid.yaml --out out
