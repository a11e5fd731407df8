#!/usr/bin/env bash
# Sets up, builds and runs the whole test suite through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
# Tools are installed by setup.sh, so a test that would skip for a missing tool fails here.
RIGC_REQUIRE_TOOLS=1 ctest --test-dir build --output-on-failure -j "$(nproc)"
