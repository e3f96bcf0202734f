"""eomgen: symbolic equations of motion M(q) q̈ + C(q, q̇) q̇ + g(q) = τ for robots.

The pipeline, one module per stage::

    eomgen.load(path) -> RobotModel -> eomgen.derive(model) -> Dynamics -> eomgen.verify(dynamics)

>>> import eomgen
>>> arm = eomgen.load(eomgen.example_path("planar_2link"))
>>> dyn = eomgen.derive(arm)
>>> dyn.joint_names
('joint1', 'joint2')
"""

from __future__ import annotations

__version__ = "0.1.0"

from .dynamics import Dynamics, derive  # noqa: E402
from .errors import DescriptionError, EomgenError, UnsupportedError  # noqa: E402
from .model import RobotModel  # noqa: E402
from .parsers import load  # noqa: E402
from .robots import example_path  # noqa: E402
from .verify import verify  # noqa: E402

__all__ = [
    "load", "derive", "verify", "example_path", "RobotModel", "Dynamics",
    "EomgenError", "DescriptionError", "UnsupportedError", "__version__",
]
