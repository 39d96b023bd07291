"""Labelled single-view depth clouds of procedural objects, rendered through the task's camera path."""
