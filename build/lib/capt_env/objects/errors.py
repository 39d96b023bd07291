"""Errors raised while reading a user's object file."""

from __future__ import annotations


class ObjectFileError(ValueError):
    """An object file that cannot be loaded; the message names the file and the element at fault."""
