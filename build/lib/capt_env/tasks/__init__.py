"""ManiSkill tasks of capt-env: one task class, configured per object (see ``open_articulated``)."""

from capt_env.tasks.config import CameraConfig, TaskConfig

__all__ = ["CameraConfig", "TaskConfig"]
