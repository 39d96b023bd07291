"""Check that SAPIEN can find a Vulkan rendering device, and explain how to get one when it cannot."""

from __future__ import annotations

import contextlib
import subprocess
from collections.abc import Iterator

INSTALL_HINT = (
    "SAPIEN needs a Vulkan device, even for state-only simulation. On a machine without a GPU, install "
    "Mesa >= 25 software Vulkan (lavapipe); on Debian 12 it is in bookworm-backports:\n"
    "  echo 'deb http://deb.debian.org/debian bookworm-backports main' "
    "> /etc/apt/sources.list.d/backports.list\n"
    "  apt-get update && apt-get install -t bookworm-backports mesa-vulkan-drivers libvulkan1\n"
    "or simply run `bash scripts/setup.sh`, which does this when no working device is found. "
    "Debian 12's own Mesa 22.3 lacks descriptorBindingPartiallyBound and does not work. "
    "Run `capt doctor` to see what SAPIEN finds."
)


class RendererUnavailableError(RuntimeError):
    """No Vulkan device usable by SAPIEN; the message says what to install."""


def device_summary() -> str:
    """SAPIEN's own description of the render devices it sees (empty string if SAPIEN fails)."""
    try:
        import sapien

        return str(sapien.render.get_device_summary())
    except Exception as exc:  # noqa: BLE001 - we report whatever went wrong
        return f"(sapien failed: {exc})"


def mesa_version() -> str | None:
    """Installed Debian mesa-vulkan-drivers version, or None when dpkg does not know it."""
    try:
        out = subprocess.run(
            ["dpkg-query", "-W", "-f=${Version}", "mesa-vulkan-drivers"],
            capture_output=True, text=True, check=False, timeout=10,
        )
    except (OSError, subprocess.TimeoutExpired):
        return None
    return out.stdout.strip() or None


def renderer_works() -> tuple[bool, str]:
    """Try to create a SAPIEN render device; return (ok, message)."""
    try:
        import sapien

        sapien.render.RenderSystem()
    except Exception as exc:  # noqa: BLE001
        return False, f"{exc}"
    return True, "ok"


@contextlib.contextmanager
def translate_render_error() -> Iterator[None]:
    """Turn SAPIEN's raw 'failed to find a rendering device' into :class:`RendererUnavailableError`."""
    try:
        yield
    except RuntimeError as exc:
        text = str(exc).lower()
        if "render" in text and ("device" in text or "vulkan" in text):
            raise RendererUnavailableError(
                f"SAPIEN could not create a rendering device ({exc}).\n{INSTALL_HINT}"
            ) from exc
        raise
