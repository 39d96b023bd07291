"""``capt doctor``: what SAPIEN can render with, the versions installed, and what to install."""

from __future__ import annotations

import argparse

from capt_common.json_report import machine_info, write_json
from capt_env.rendering import INSTALL_HINT, device_summary, mesa_version, renderer_works


def add_arguments(parser: argparse.ArgumentParser) -> None:
    del parser  # no options of its own


def run(args: argparse.Namespace) -> int:
    versions = machine_info()
    ok, message = renderer_works()
    summary = device_summary()
    mesa = mesa_version()
    print("capt doctor")
    for key, value in versions.items():
        print(f"  {key:<11} {value}")
    print(f"  mesa-vulkan {mesa or 'not installed (dpkg)'}")
    print("SAPIEN render devices:")
    print("  " + summary.strip().replace("\n", "\n  "))
    if ok:
        print("rendering: OK")
    else:
        print(f"rendering: FAILED ({message})\n{INSTALL_HINT}")
    write_json(args.json, {"rendering_ok": ok, "render_message": message, "device_summary": summary,
                           "mesa_vulkan_drivers": mesa, "versions": versions})
    return 0 if ok else 1
