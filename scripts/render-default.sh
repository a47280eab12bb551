#!/usr/bin/env bash
# README's first command: install dependencies, build, render the built-in Cornell box.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
./build/photonvr render cornell --out out/cornell
