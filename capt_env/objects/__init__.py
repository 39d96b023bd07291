"""Procedural articulated objects (boxes + 1-DoF joints) for the CAPT tasks, and user URDF/MJCF files.

Conventions shared by every category (see ``spec.py``): object frame +z up, resting on z = 0, the
front (handles, door fronts) facing -x; state 0 = closed/folded; +state opens. Entry points:
``registry.make_object(category, instance_id)``, ``splits.instance_ids(category, split)``,
``builder.build_articulated_object(scene, spec, name)`` and ``user_files.load_user_object``.
This package file imports nothing heavy: the simulator is only needed by ``builder``, ``scene``
and ``user_files``.
"""
