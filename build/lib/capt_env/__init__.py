"""capt-env: ManiSkill3 environments for opening articulated objects, and CAPT perception for them.

``import capt_env`` registers the env ids (see :mod:`capt_env.registration`).
"""

from capt_env.registration import env_id, register_envs

__version__ = "0.1.0"
__all__ = ["env_id", "register_envs", "__version__"]

register_envs()
