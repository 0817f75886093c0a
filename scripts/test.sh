#!/usr/bin/env bash
# Runs every Sylva test (README's test command). Needs ../shared/test-data or SYLVA_DATA.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export XDG_RUNTIME_DIR=/tmp/sylva-xdg WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
cargo test --release --workspace "$@"
