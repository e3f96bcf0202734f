"""Deprecated path: the ``pinocchio.Model`` built from a :class:`~eomgen.model.RobotModel` moved
to :mod:`eomgen.numeric.pinocchio` (with eomgen's other Pinocchio adapters); the names stay
importable from here.
"""

from __future__ import annotations

from ..numeric.pinocchio import PinocchioModel, to_pinocchio

__all__ = ["PinocchioModel", "to_pinocchio"]
