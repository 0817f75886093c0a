#!/usr/bin/env bash
# Installs everything Sylva needs on a fresh Debian/Ubuntu machine; fast no-op when already there.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  libopencv-dev clang libclang-dev   # OpenCV bindings (sylva-tracking, feature `opencv`)
  mesa-vulkan-drivers libvulkan1     # lavapipe: Vulkan on the CPU for headless rendering and golden images
  xvfb x11-apps imagemagick          # windows and screenshots in tests
  pkg-config
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
# The Khronos glTF validator runs on node; some images ship node (with npm) from elsewhere.
command -v npm >/dev/null || missing+=(nodejs npm)
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi

# Mobile targets, type-checked in CI (no NDK or Xcode needed for `cargo check`).
if command -v rustup >/dev/null; then
  installed=$(rustup target list --installed)
  for t in aarch64-linux-android aarch64-apple-ios; do
    grep -qx "$t" <<<"$installed" || rustup target add "$t" >/dev/null
  done
fi

# The Khronos glTF validator (npm package), pinned in tools/gltf-validator/package.json.
if [ -f tools/gltf-validator/package.json ] && [ ! -d tools/gltf-validator/node_modules/gltf-validator ]; then
  echo "setup: installing gltf-validator"
  (cd tools/gltf-validator && npm install --no-audit --no-fund --silent >/dev/null)
fi

# A real glTF reader for the export tests: glTF Transform, pinned in tools/gltf-reader/package.json.
if [ -f tools/gltf-reader/package.json ] && { [ ! -d tools/gltf-reader/node_modules/@gltf-transform/core ] ||
  [ ! -d tools/gltf-reader/node_modules/@gltf-transform/extensions ]; }; then
  echo "setup: installing @gltf-transform/core and /extensions"
  (cd tools/gltf-reader && npm install --no-audit --no-fund --silent >/dev/null)
fi

# Quiet Mesa, skip GL probing: lavapipe through Vulkan.
mkdir -p /tmp/sylva-xdg && chmod 700 /tmp/sylva-xdg
