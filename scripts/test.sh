#!/usr/bin/env bash
# README's second command: install dependencies, build, run the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
# The Vulkan tests run on lavapipe here: a missing Vulkan driver fails them instead of skipping.
export PVR_REQUIRE_VULKAN=1
ctest --test-dir build --output-on-failure -j"$(nproc)"
