"""Fixed joints: no motion, no coordinate (NQ = NV = 0); the child frame is the joint frame."""

from __future__ import annotations

from .base import JointKind


class Fixed(JointKind):
    name = "fixed"
    nq = nv = 0


FIXED = Fixed()

__all__ = ["FIXED", "Fixed"]
