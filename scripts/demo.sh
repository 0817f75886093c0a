#!/usr/bin/env bash
# Runs Sylva's demo (README's first command).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export XDG_RUNTIME_DIR=/tmp/sylva-xdg WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
# Both binaries: the lean `sylva` hands the window and the replay to `sylva-app` beside it.
cargo build --release -p sylva-app --bins
cargo run --release -p sylva-app --bin sylva -- "$@"
