"""CAPT: category-level articulation estimation from one point cloud (PCT encoder, voting heads).

Never imports ManiSkill, SAPIEN or Gymnasium: it takes arrays, so it runs on real sensor clouds too.
"""
