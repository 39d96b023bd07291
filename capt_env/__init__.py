"""capt-env: ManiSkill3 environments for opening articulated objects, and CAPT perception for them.

``import capt_env`` registers the env ids (see :mod:`capt_env.registration`). ``capt_env.make_env``
(:mod:`capt_env.env_factory`) makes an env wrapped for the policies; it is imported on first use, so
that ``import capt_env`` stays light.
"""

from capt_env.registration import env_id, register_envs

__version__ = "0.1.0"
__all__ = ["env_id", "make_env", "register_envs", "__version__"]


def __getattr__(name: str):  # PEP 562: the lazy ``make_env``
    if name == "make_env":
        from capt_env.env_factory import make_env

        return make_env
    raise AttributeError(f"module 'capt_env' has no attribute {name!r}")


register_envs()
