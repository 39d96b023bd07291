"""PPO (stable-baselines3) on joint-axis observations.

``agents.ppo.config`` (the typed config), ``agents.ppo.train`` (``train_ppo``: vector envs, PPO,
checkpoints, resume) and ``agents.ppo.policy`` (``PPOPolicy``: a trained model as an opener-like
policy). Import the submodules; this package imports nothing heavy.
"""
