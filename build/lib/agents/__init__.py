"""Policies that open articulated objects from joint-axis observations: scripted and PPO."""
