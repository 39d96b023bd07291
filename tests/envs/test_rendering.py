"""A missing Vulkan device is reported with what to install, not SAPIEN's raw message."""

from __future__ import annotations

import pytest

from capt_env.rendering import RendererUnavailableError, renderer_works, translate_render_error


def test_render_device_error_is_translated() -> None:
    with pytest.raises(RendererUnavailableError, match="bookworm-backports") as exc:
        with translate_render_error():
            raise RuntimeError("failed to find a rendering device")
    assert "capt doctor" in str(exc.value)


def test_other_errors_pass_through() -> None:
    with pytest.raises(RuntimeError, match="unrelated"):
        with translate_render_error():
            raise RuntimeError("unrelated")


def test_this_machine_renders() -> None:
    ok, message = renderer_works()
    assert ok, message
