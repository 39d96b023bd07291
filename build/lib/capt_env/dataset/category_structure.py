"""The output-channel structure a CAPT model needs for a category, read off its procedural instances."""

from __future__ import annotations

from functools import cache


@cache
def category_structure(category: str, instances: int = 200) -> dict:
    """``max_parts``, ``max_joints``, ``joint_types`` and ``joint_child_parts`` over the first
    ``instances`` instances of ``category`` (the paper's "fully prepared" channels: the maximum over
    the category; unused channels are masked). Raises ValueError when joint slots disagree in type or
    child part between instances, since one channel must mean one joint."""
    from capt_env.objects.registry import make_object

    max_parts, types, children = 0, {}, {}
    for iid in range(instances):
        spec = make_object(category, iid)
        max_parts = max(max_parts, len(spec.links))
        names = [link.name for link in spec.links]
        for k, joint in enumerate(spec.joints):
            child = names.index(joint.child)
            if types.setdefault(k, joint.type) != joint.type or children.setdefault(k, child) != child:
                raise ValueError(f"{category}: joint slot {k} differs between instances")
    n = len(types)
    return {
        "max_parts": max_parts,
        "max_joints": n,
        "joint_types": [types[k] for k in range(n)],
        "joint_child_parts": [children[k] for k in range(n)],
    }
