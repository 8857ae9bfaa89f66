#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the libFuzzer harnesses into build-fuzz/ (Clang, ASan + UBSan, PLAF_FUZZ=ON) and runs each
# for N seconds on its seed corpus and dictionary (tests/fuzz/README.md).
#
#   bash tests/fuzz/run.sh [SECONDS] [HARNESS...]     SECONDS per harness (default 60);
#                                                      HARNESS: airfoil surface msh background yaml
# Environment: JOBS (build parallelism, default 1), CXX_FUZZ (default clang++),
#              BUILD_FUZZ (default <repo>/build-fuzz), FUZZ_ARGS (extra libFuzzer flags).
# Leaves: build-fuzz/fuzz-corpus/<harness>/   the corpus (seeds + what libFuzzer kept; reused)
#         build-fuzz/fuzz-findings/<harness>/ crash-*, leak-*, timeout-*, oom-* reproducers
#         build-fuzz/fuzz-logs/<harness>.log  libFuzzer's output; fuzz-logs/summary.txt the table
# Exit status: 0 when no harness reported a finding, 1 otherwise.
set -euo pipefail

seconds=${1:-60}
shift || true
harnesses=("$@")
[ ${#harnesses[@]} -eq 0 ] && harnesses=(airfoil surface msh background yaml)

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${BUILD_FUZZ:-$root/build-fuzz}
here=$root/tests/fuzz

# 1. Configure and build (only the harnesses and the libraries they link) --------------------
cmake -S "$root" -B "$build" -DPLAF_FUZZ=ON -DPLAF_BUILD_TESTS=OFF -DCMAKE_CXX_COMPILER="${CXX_FUZZ:-clang++}" \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" >/dev/null
targets=()
for h in "${harnesses[@]}"; do targets+=("fuzz_$h"); done
cmake --build "$build" -j "${JOBS:-1}" --target "${targets[@]}"

# 2. Seed corpora: small valid files of the repository, copied (never moved) into the corpus ----
corpus=$build/fuzz-corpus
# copy SRC DEST [PREFIX]: the file, with PREFIX (a selector byte, printf format) in front
copy() { mkdir -p "$(dirname "$2")"; { [ -n "${3:-}" ] && printf "$3"; cat "$1"; } > "$2"; }
seed_airfoil() {
  for f in "$root"/data/airfoils/*.dat "$root"/data/sections/*.dat "$here"/seeds/airfoil/*; do
    copy "$f" "$corpus/airfoil/seed-$(basename "$f")"
  done
}
seed_surface() {  # selector byte % 6: 0 stl, 1 obj, 2 off, 3 ply, 4 fmt, 5 p3d (fuzz_surface.cpp)
  for f in "$here"/seeds/surface/*; do
    case "$f" in
      *.stl) sel='\x00' ;; *.obj) sel='\x01' ;; *.off) sel='\x02' ;; *.ply) sel='\x03' ;; *.fmt) sel='\x04' ;;
    esac
    copy "$f" "$corpus/surface/seed-$(basename "$f")" "$sel"
  done
  copy "$here/seeds/surface/two_blocks.fmt" "$corpus/surface/seed-two_blocks.p3d" '\x05'
  # A published Plot3D file from the data root, when one holds it (11 kB; docs/data.md).
  local p3d
  if p3d=$("$root/build/apps/plaf" data surfaces/sphere_cube6_even.fmt 2> /dev/null); then
    copy "$p3d" "$corpus/surface/seed-sphere_cube6_even.fmt" '\x04'
  fi
}
seed_msh() {
  for f in "$here"/seeds/msh/*.msh "$here"/seeds/background/*.msh; do copy "$f" "$corpus/msh/seed-$(basename "$f")"; done
}
seed_background() {  # selector byte % 4: 0 msh 2D, 1 msh 3D, 2 mesh/sol 2D, 3 mesh/sol 3D (fuzz_background.cpp)
  local b=$here/seeds/background
  copy "$b/quad_p2_2d.msh" "$corpus/background/seed-quad_p2_2d.msh" '\x00'
  copy "$here/seeds/msh/square_tri6.msh" "$corpus/background/seed-square_tri6_no_view.msh" '\x00'
  copy "$b/tet_3d.msh" "$corpus/background/seed-tet_3d.msh" '\x01'
  copy "$b/tet_p2_3d.msh" "$corpus/background/seed-tet_p2_3d.msh" '\x01'
  { printf '\x02'; cat "$b/square_2d.mesh"; printf '\x00'; cat "$b/square_2d.sol"; } > "$corpus/background/seed-square_2d.meshsol"
  { printf '\x03'; cat "$b/tets_3d.mesh"; printf '\x00'; cat "$b/tets_3d.sol"; } > "$corpus/background/seed-tets_3d.meshsol"
}
seed_yaml() {
  for f in "$root"/configs/*.yaml; do copy "$f" "$corpus/yaml/seed-$(basename "$f")"; done
}

# 3. Run each harness ---------------------------------------------------------------------
mkdir -p "$build/fuzz-logs"
summary=$build/fuzz-logs/summary.txt
printf '%-11s %7s %10s %9s %7s %7s %6s  %s\n' harness seconds execs exec/s cov ft corpus result > "$summary"
status=0
for h in "${harnesses[@]}"; do
  mkdir -p "$corpus/$h" "$build/fuzz-findings/$h"
  "seed_$h"
  log=$build/fuzz-logs/$h.log
  start=$(date +%s)
  set +e
  # -timeout: an input taking more than 10 s is a hang; -rss_limit_mb/-malloc_limit_mb: 2 GB.
  # ${FUZZ_ARGS} is split on purpose (several flags).
  # shellcheck disable=SC2086
  "$build/tests/fuzz/fuzz_$h" "$corpus/$h" -dict="$here/dict/$h.dict" -max_total_time="$seconds" -timeout=10 \
      -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/fuzz-findings/$h/" ${FUZZ_ARGS:-} > "$log" 2>&1
  rc=$?
  set -e
  elapsed=$(( $(date +%s) - start ))
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  last=$(grep -E '^#[0-9]+' "$log" | tail -1 || true)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<< "$last")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<< "$last")
  units=$(sed -n 's/.* corp: \([0-9]*\)\/.*/\1/p' <<< "$last")
  if [ "$rc" -eq 0 ]; then
    result=ok
  else
    status=1
    result="FINDING (exit $rc): $(ls -t "$build/fuzz-findings/$h" | head -1) — see $log"
  fi
  printf '%-11s %7s %10s %9s %7s %7s %6s  %s\n' "$h" "$elapsed" "${execs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" \
         "${units:-?}" "$result" >> "$summary"
  echo "fuzz_$h: $result"
done
cat "$summary"
exit $status
