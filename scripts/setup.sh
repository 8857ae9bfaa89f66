#!/usr/bin/env bash
# Installs the Debian packages plaf needs to build and test, and only those that are missing.
# Runs as root (as on the project's machines) or through sudo. Does nothing when all are present.
set -euo pipefail
packages=(build-essential cmake libeigen3-dev libopenmesh-dev libtet1.5-dev libyaml-cpp-dev
          doctest-dev libcairo2-dev zlib1g-dev libcgns-dev python3 python3-dev python3-numpy
          pybind11-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "setup: installing ${missing[*]}" >&2
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
