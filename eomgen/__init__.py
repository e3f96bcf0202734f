"""eomgen: symbolic equations of motion M(q) q̈ + C(q, q̇) q̇ + g(q) = τ for robots."""

from __future__ import annotations

__version__ = "0.1.0"

from .errors import DescriptionError, EomgenError, UnsupportedError  # noqa: E402
from .parsers import load  # noqa: E402

__all__ = ["load", "EomgenError", "DescriptionError", "UnsupportedError", "__version__"]
