"""A contact of a scene (:class:`Contact`): a frame held still at a point (3 rows of ``J_c``) or
over a surface (6 rows). Plain data; the contact dynamics are computed from it by
:mod:`eomgen.symbolic.frames` (generated) and :mod:`eomgen.numeric.contacts` (numerically), whose
docstring gives the conventions (axes, signs, Baumgarte terms)."""

from __future__ import annotations

from dataclasses import dataclass

#: The kinds of contact: a point contact holds the frame origin, a surface contact the frame.
POINT, SURFACE = "point", "surface"


@dataclass(frozen=True)
class Contact:
    """A contact on ``frame``: ``kind`` point (3D) or surface (6D), friction coefficient
    ``mu`` (None: no cone check), Baumgarte gains ``kp`` [1/s²] and ``kd`` [1/s], the contact
    ``normal`` (point contacts, world axes) and a ``name``."""

    frame: str
    kind: str = POINT
    mu: float | None = None
    kp: float = 0.0
    kd: float = 0.0
    normal: tuple[float, float, float] = (0.0, 0.0, 1.0)
    name: str = ""

    def __post_init__(self):
        if self.kind not in (POINT, SURFACE):
            raise ValueError(f"contact '{self.name or self.frame}': kind must be 'point' or "
                             f"'surface', got {self.kind!r}")
        if self.mu is not None and not self.mu >= 0:
            raise ValueError(f"contact '{self.name or self.frame}': friction coefficient "
                             f"{self.mu} is negative (μ ≥ 0)")
        if not (self.kp >= 0 and self.kd >= 0):
            raise ValueError(f"contact '{self.name or self.frame}': Baumgarte gains must be "
                             "non-negative")

    @property
    def size(self) -> int:
        """Rows of the contact in ``J_c``: 3 (point) or 6 (surface)."""
        return 3 if self.kind == POINT else 6
