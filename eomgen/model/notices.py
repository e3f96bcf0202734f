"""Findings about a description that do not stop it from loading (:class:`Notice`)."""

from __future__ import annotations

import enum
import warnings
from dataclasses import dataclass
from typing import Iterable

from ..errors import (
    DescriptionError,
    InvalidInertiaError,
    PhysicalConsistencyWarning,
    UnsupportedError,
    UnsupportedFeatureWarning,
    one_line,
)

class NoticeKind(enum.Enum):
    """What a :class:`Notice` is about."""

    TRIANGLE_INEQUALITY = "triangle inequality"  # a link inertia that is not physical
    NO_MASS = "moves no mass"                    # a joint whose row of M(q) is zero
    MIMIC = "mimic"                              # a URDF <mimic> coupling read as independent
    FLOATING_BASE = "floating base"              # a root that looks free, read as fixed
    NOT_MODELLED = "not modelled"                # a feature left out (MJCF tendons, springs)

#: The kinds about masses and inertias (:class:`~eomgen.errors.PhysicalConsistencyWarning`).
_INERTIAL = (NoticeKind.TRIANGLE_INEQUALITY, NoticeKind.NO_MASS)


@dataclass(frozen=True)
class Notice:
    """A finding about a description that does not stop it from loading: a warning, or an error
    under ``strict`` (``--strict``).

    Parsers record notices on the model (:attr:`RobotModel.notices`) instead of warning at
    once when asked to (``defer_notices=True``), so that a scene can first say which of them
    still matter: a notice is moot when none of the ``joints`` it concerns moves, or every one
    of the ``links`` it concerns is dropped (see :func:`eomgen.reduction.apply_scene`).

    Attributes
    ----------
    kind:
        What it is about.
    source, element, problem:
        The file, the element and the finding, as in :class:`~eomgen.errors.DescriptionError`.
    fallback:
        How eomgen reads the description anyway (e.g. "read as an independent joint"); empty
        for values used as they are (a non-physical inertia).
    links, joints:
        The links and joints the finding concerns.
    """

    kind: NoticeKind
    source: str
    element: str
    problem: str
    fallback: str = ""
    links: tuple[str, ...] = ()
    joints: tuple[str, ...] = ()

    @property
    def category(self) -> type[Warning]:
        """The warning class issued without ``strict``."""
        if self.kind in _INERTIAL:
            return PhysicalConsistencyWarning
        return UnsupportedFeatureWarning

    @property
    def error(self) -> type[DescriptionError]:
        """The error class raised under ``strict``."""
        if self.kind in _INERTIAL:
            return InvalidInertiaError
        return UnsupportedError

    @property
    def message(self) -> str:
        """The warning's text: one line naming the file, the element and the finding."""
        tail = f"; {self.fallback}" if self.fallback else ""
        return one_line(f"{self.source}: {self.element}: {self.problem}{tail}")

    def emit(self, strict: bool = False, stacklevel: int = 2) -> None:
        """Warn (``category``), or under ``strict`` raise ``error`` saying it was refused."""
        if strict:
            raise self.error(self.source, self.element,
                             self.problem + " (refused under --strict)")
        warnings.warn(self.message, self.category, stacklevel=stacklevel + 1)


def emit_notices(notices: Iterable[Notice], strict: bool = False) -> None:
    """Warn about each notice in order, or under ``strict`` raise the first one's error."""
    for notice in notices:
        notice.emit(strict, stacklevel=3)
