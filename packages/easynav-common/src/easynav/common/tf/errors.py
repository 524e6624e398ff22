"""Errors of the TF buffer: every message names the frames, the time asked and what exists."""

from __future__ import annotations


class TransformError(LookupError):
    """A transform cannot be given. Base of the three TF lookup failures."""


class FrameLookupError(TransformError):
    """A frame was never received by the buffer (tf2's LookupException)."""


class ConnectivityError(TransformError):
    """Both frames exist but are in separate trees (tf2's ConnectivityException)."""


class ExtrapolationError(TransformError):
    """The time asked is outside the time range held for a frame on the chain."""
