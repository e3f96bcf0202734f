"""Exceptions raised by eomgen.

Every error a user can provoke with bad input is a subclass of :class:`EomgenError`. The
message is one line naming the file, the element and what is wrong, so the CLI can print it
as is and exit with code 2.
"""

from __future__ import annotations

import warnings


def one_line(text: str) -> str:
    """``text`` with line breaks and other non-printable characters escaped (``\\n``,
    ``\\u2028``), so that a message built from file content (names, paths) stays on one line."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


class EomgenError(Exception):
    """Base class of every error eomgen raises on bad input or impossible requests."""


class DescriptionError(EomgenError):
    """A robot description (URDF, DH table, eomgen YAML) is malformed or not physical.

    Parameters
    ----------
    source:
        The file (or other source label) the description came from.
    element:
        The element at fault, e.g. ``"link 'arm1' <inertial>"``; empty when the whole file is at
        fault (not parseable at all).
    problem:
        What is wrong, in a short phrase.
    """

    def __init__(self, source: str, element: str, problem: str):
        self.source = str(source)
        self.element = element
        self.problem = problem
        where = f"{self.source}: {element}: " if element else f"{self.source}: "
        super().__init__(one_line(where + problem))


class UnsupportedError(DescriptionError):
    """The description is valid but uses a feature eomgen does not model yet (mimic, floating)."""


class PhysicalConsistencyWarning(UserWarning):
    """A rigid body's inertia is positive semi-definite but breaks the triangle inequality."""


class VerificationError(EomgenError):
    """Raised by :func:`eomgen.verify.verify` callers that ask for failures to raise."""


def warn_physical(source: str, element: str, problem: str, strict: bool) -> None:
    """Warn about a non-physical but usable value, or raise under ``strict``."""
    if strict:
        raise DescriptionError(source, element, problem + " (refused under --strict)")
    warnings.warn(one_line(f"{source}: {element}: {problem}"), PhysicalConsistencyWarning,
                  stacklevel=3)
