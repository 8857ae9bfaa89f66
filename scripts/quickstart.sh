#!/usr/bin/env bash
# One command on a fresh Debian 12 machine: install what is missing, build (Release) and run the
# default job (configs/annulus.yaml) into out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j2
./build/apps/plaf run configs/naca0012_hybrid.yaml --out out
