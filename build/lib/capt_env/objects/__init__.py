"""Procedural articulated objects (boxes + 1-DoF joints) for the CAPT tasks, and user URDF/MJCF files.

Conventions shared by every category (see ``spec.py``): object frame +z up, resting on z = 0, the
front (handles, door fronts) facing -x; state 0 = closed/folded; +state opens. Entry points:
``make_object(category, instance_id)`` and ``instance_ids(category, split)`` (also importable from
here), ``builder.build_articulated_object(scene, spec, name)`` and ``user_files.load_user_object``.
This package file imports nothing heavy: the simulator is only needed by ``builder``, ``scene``
and ``user_files``.
"""

from capt_env.objects.registry import CATEGORIES, make_object
from capt_env.objects.splits import instance_ids

__all__ = ["CATEGORIES", "instance_ids", "make_object"]
