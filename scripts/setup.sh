#!/usr/bin/env bash
# Set up capt-env from nothing on Debian 12 (bookworm): a software Vulkan driver when no working Vulkan
# device exists, a virtual environment in .venv, the CPU build of torch, then the package itself.
# Idempotent: a second run checks each step and skips what is already done.
#
#   bash scripts/setup.sh            # runtime only
#   bash scripts/setup.sh --test     # also the test extra (pytest, ruff)
set -euo pipefail

cd "$(dirname "$0")/.."
ROOT=$(pwd)
VENV=${CAPT_VENV:-$ROOT/.venv}
PY=${PYTHON:-python3}
TORCH_SPEC=${CAPT_TORCH_SPEC:-torch==2.13.0}
EXTRAS=""
[ "${1:-}" = "--test" ] && EXTRAS="[test]"

log() { printf '[setup] %s\n' "$*"; }

as_root() {
  if [ "$(id -u)" = 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@"; else
    log "need root for: $*"; exit 1; fi
}

# 1. Software Vulkan (Mesa >= 25, lavapipe) from bookworm-backports when no usable Vulkan ICD is present.
mesa_ok() {
  local v
  v=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
  [ -n "$v" ] && dpkg --compare-versions "$v" ge 25 && dpkg-query -W libvulkan1 >/dev/null 2>&1
}
nvidia_icd() { ls /usr/share/vulkan/icd.d/nvidia_icd.json /etc/vulkan/icd.d/nvidia_icd.json >/dev/null 2>&1; }

if [ "${CAPT_SKIP_APT:-0}" != 1 ] && ! mesa_ok && ! nvidia_icd; then
  if grep -q bookworm /etc/os-release 2>/dev/null; then
    log "installing Mesa software Vulkan from bookworm-backports"
    if ! grep -rqs bookworm-backports /etc/apt/sources.list /etc/apt/sources.list.d/; then
      printf 'Types: deb\nURIs: http://deb.debian.org/debian\nSuites: bookworm-backports\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
        | as_root tee /etc/apt/sources.list.d/bookworm-backports.sources >/dev/null
    fi
    as_root apt-get update -qq
    DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq -t bookworm-backports \
      mesa-vulkan-drivers libvulkan1 >/dev/null
  else
    log "not Debian 12: install Mesa >= 25 Vulkan drivers (lavapipe) with your package manager"
  fi
fi

# 2. Virtual environment.
if [ ! -x "$VENV/bin/python" ]; then
  log "creating $VENV"
  "$PY" -m venv "$VENV"
  "$VENV/bin/python" -m pip install -q --upgrade pip
fi
VPY="$VENV/bin/python"

# 3. CPU torch first, so that no dependency pulls a CUDA build.
if ! "$VPY" -c "import torch" >/dev/null 2>&1; then
  log "installing $TORCH_SPEC"
  "$VPY" -m pip install -q "$TORCH_SPEC"
fi

# 4. The package (editable), re-installed only when pyproject.toml changed.
STAMP="$VENV/.capt-env-installed"
WANT="$(sha256sum pyproject.toml | cut -c1-16)$EXTRAS"
if [ ! -f "$STAMP" ] || ! grep -qxF -- "$WANT" "$STAMP" \
   || ! "$VPY" -c "import importlib.metadata as m; m.version('capt-env')" >/dev/null 2>&1; then
  log "installing capt-env$EXTRAS"
  "$VPY" -m pip install -q -e ".$EXTRAS"
  echo "$WANT" >"$STAMP"
fi
log "ready: $VENV/bin/capt"
