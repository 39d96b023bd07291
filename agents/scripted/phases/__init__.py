"""The scripted opener's phases, one small class each with ``step(ctx) -> (action, next phase)``,
and the per-episode state they share (:class:`~agents.scripted.phases.context.OpenerContext`, which
keeps the part-kind strategy of the grasp under way, :mod:`agents.scripted.part_strategies`).

``base`` (the phase interface, actions, moves), ``context`` (the shared state), ``reach`` (pre-grasp,
approach, and the lift from below's two moves), ``grasp`` (closing the fingers), ``pull``, ``release``
(release, retreat, re-grasp, waiting for a falling door, done).
"""
