"""Exceptions raised by eomgen.

Every error a user can provoke with bad input is a subclass of :class:`EomgenError`. The
message is one line naming the file, the element and what is wrong, so the CLI can print it
as is and exit with code 2. Each kind of problem has its own class, so that callers (and
tests) can tell them apart without reading messages::

    EomgenError
    ├── DescriptionError          a description file is unusable (file, element, problem)
    │   ├── UnreadableFileError   missing, unreadable or not UTF-8
    │   ├── UnknownFormatError    unknown file suffix; YAML that is neither format
    │   ├── TooLargeError         file size, YAML nodes or depth, joint count, simplify limit
    │   ├── XMLSyntaxError        malformed XML
    │   ├── ForbiddenXMLError     entity declarations, external entities or DTDs
    │   ├── YAMLFormatError       YAML syntax, aliases, duplicate keys, Python tags
    │   ├── SchemaError           a missing, unknown or repeated element, attribute or key;
    │   │                         a value of the wrong kind or count; an unknown joint type
    │   ├── InvalidNumberError    text that is not a finite real number (or a permitted
    │   │                         expression), or a magnitude above MAX_MAGNITUDE
    │   ├── ParameterError        parameter names (keywords, reserved, duplicate), undeclared
    │   │                         symbols, parameters without a value
    │   ├── InvalidInertiaError   negative or non-finite mass, inertia not symmetric positive
    │   │                         semi-definite, triangle inequality (under strict)
    │   ├── InvalidAxisError      zero or non-finite joint axis
    │   ├── InvalidActuatorError  a joint's drive that is not physical: negative armature,
    │   │                         rotor inertia, damping or friction, a friction width or
    │   │                         stiffness ≤ 0, gear ratio 0, a flexible joint without
    │   │                         motor inertia
    │   ├── KinematicTreeError    duplicate names, undefined links or joints, two parents,
    │   │                         cycles, disconnected links, no root
    │   ├── InvalidLoopError      a loop closure that constrains nothing, a planar loop whose
    │   │                         plane does not hold the motion, loops leaving no freedom
    │   ├── UnsupportedError      floating and planar joints; mimic joints read as
    │   │                         independent (couplings=False) under strict
    │   └── SceneError            a scene file (eomgen.scene) that is malformed or does not fit
    │                             the robot: unknown key, link or joint, a lock on a joint that
    │                             is not movable, a tip not below the base, a bad payload
    ├── GenerationError           a code generation request that cannot be carried out
    ├── AnalysisError             a bench or simulation request that cannot be carried out
    ├── IdentificationError       measurements that cannot be used (``eomgen identify``)
    └── VerificationError

The classes split problems by *kind*: text that does not read as a number is an
:class:`InvalidNumberError` wherever it stands (a mass of ``nan`` as much as an axis of
``0 nan 1``); values that read well but describe something impossible are classed by what they
describe (:class:`InvalidInertiaError` for a mass of ``-1``, :class:`InvalidAxisError` for an
axis of ``0 0 0``).
"""

from __future__ import annotations

import contextlib
import warnings
from typing import Callable, Iterable, Iterator


def closest_name(name: str, known: Iterable[str]) -> str | None:
    """The closest of ``known`` to ``name`` (:func:`difflib.get_close_matches`), or None."""
    import difflib  # here: only when an error is being written

    hint = difflib.get_close_matches(name, list(known), n=1)
    return hint[0] if hint else None


def did_you_mean(name: str, known: Iterable[str]) -> str:
    """``"; did you mean 'x'?"`` for the closest of ``known``, or an empty string: the tail of
    a one-line error about an unknown name."""
    hint = closest_name(name, known)
    return f"; did you mean '{hint}'?" if hint else ""


def one_line(text: str) -> str:
    """``text`` with line breaks and other non-printable characters escaped (``\\n``,
    ``\\u2028``), so that a message built from file content (names, paths) stays on one line."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


@contextlib.contextmanager
def recorded_warnings(tidy: Callable[[str], str] = one_line) -> Iterator[list[str]]:
    """Within the block, warnings are shown as usual and their messages, passed through
    ``tidy``, collected in the list yielded (the CLI and the derivation cache store them, so
    that a cached run shows them again)."""
    notices: list[str] = []
    shown = warnings.showwarning

    def record(message, *args, **kwargs):
        notices.append(tidy(str(message)))
        shown(message, *args, **kwargs)

    warnings.showwarning = record
    try:
        yield notices
    finally:
        warnings.showwarning = shown


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


class UnreadableFileError(DescriptionError):
    """The description file is missing, cannot be read or is not UTF-8 text."""


class UnknownFormatError(DescriptionError):
    """eomgen cannot tell the file's format (unknown suffix; YAML that is neither a DH table nor
    an eomgen robot)."""


class TooLargeError(DescriptionError):
    """The description exceeds a limit eomgen sets to stay fast and safe (file size, YAML nodes
    or nesting, number of joints), or is too large for the chosen options (``simplify``)."""


class XMLSyntaxError(DescriptionError):
    """The URDF is not well-formed XML."""


class ForbiddenXMLError(DescriptionError):
    """The URDF or MJCF file uses XML features refused for safety: entity declarations
    (billion laughs), external entities or DTDs."""


class YAMLFormatError(DescriptionError):
    """The file is not valid YAML, or uses YAML features refused in descriptions (aliases,
    duplicate keys, Python object tags)."""


class SchemaError(DescriptionError):
    """The description does not follow its format: a required element, attribute or key is
    missing, an unknown one is given or a singleton is repeated, a value has the wrong kind or
    count, a joint type is unknown."""


class InvalidNumberError(DescriptionError):
    """Text that should be a number is not a finite real number (``nan``, ``inf``, ``abc``), not
    an expression eomgen reads, or has a magnitude above
    :data:`eomgen.model.numbers.MAX_MAGNITUDE` (1e12): the rule for every number read from a
    description or a scene, MJCF values as MuJoCo compiles them included."""


class ParameterError(DescriptionError):
    """A parameter is badly named (a Python keyword, a name eomgen reserves, a number), declared
    twice, used without being declared, or needed without a value."""


class InvalidInertiaError(DescriptionError):
    """A link's inertial data is not physical: negative or non-finite mass or centre of mass, an
    inertia that is not symmetric positive semi-definite, or (under ``strict``) principal
    moments that break the triangle inequality."""


class InvalidAxisError(DescriptionError):
    """A joint axis is zero or not finite."""


class InvalidActuatorError(DescriptionError):
    """A joint's actuator (:class:`eomgen.model.Actuator`, URDF ``<dynamics>``) reads well but
    is not physical: a negative armature, rotor inertia, viscous or Coulomb friction, a
    friction width or stiffness that is not positive, a gear ratio of 0, or zero motor inertia
    on a flexible joint. The element names the joint (``joint 'shoulder' actuator``)."""


class KinematicTreeError(DescriptionError):
    """Links and joints do not form one tree: duplicate names, a joint naming an undefined link
    (or a mimic naming an undefined joint), a link with two parents or joined to itself, a
    cycle, links not connected to the root, no root; couplings (URDF ``<mimic>``) of missing or
    fixed joints, in a cycle, or of a follower that leads another."""


class InvalidLoopError(DescriptionError):
    """A loop closure (a scene's ``loops:``, an MJCF ``connect`` or ``weld``) does not
    constrain what it claims (:mod:`eomgen.numeric.loop_checks`): no joint moves its frames
    apart, a planar loop whose plane does not hold the motion, loops that leave no degree of
    freedom or fewer than the joints named in ``actuated:``."""


class UnsupportedError(DescriptionError):
    """The description is valid but uses a feature eomgen does not model yet (floating and
    planar joints; URDF ``<mimic>`` joints read as independent under ``strict``)."""


class SceneError(DescriptionError):
    """A scene file (see :mod:`eomgen.scene`) is malformed, or does not fit the robot it is
    applied to: an unknown key, link or joint, a lock on a joint that is not movable, a tip not
    below the base, a payload whose inertia is not physical. ``source`` is the scene file."""


class PhysicalConsistencyWarning(UserWarning):
    """A rigid body's inertia is positive semi-definite but breaks the triangle inequality."""


class UnsupportedFeatureWarning(UserWarning):
    """The description uses a feature eomgen does not model and reads it in a simpler way
    (e.g. a URDF ``<mimic>`` joint read as an independent joint); refused under ``strict``."""


class GenerationError(EomgenError):
    """A code generation request that cannot be carried out (unknown backend, unknown parameter
    for ``--symbolic``, a parameter fixed without a value)."""


class AnalysisError(EomgenError):
    """A bench or simulation request that cannot be carried out (``eomgen bench``,
    ``eomgen simulate``): a missing optional dependency, a malformed list of numbers."""


class IdentificationError(EomgenError):
    """Measurements that cannot be used (``eomgen identify``): a CSV file with a missing,
    unknown or repeated column, a field that is not a finite number, too few samples for the
    base parameters, or a trajectory that does not excite them. The message names the file,
    line and column."""


class VerificationError(EomgenError):
    """Raised by :func:`eomgen.verify.verify` callers that ask for failures to raise."""


def warn_unsupported(source: str, element: str, problem: str, fallback: str,
                     strict: bool) -> None:
    """Warn that an unsupported feature is read in a simpler way (``fallback``, e.g. "read as an
    independent joint"), or raise :class:`UnsupportedError` under ``strict``."""
    if strict:
        raise UnsupportedError(source, element, problem + " (refused under --strict)")
    warnings.warn(one_line(f"{source}: {element}: {problem}; {fallback}"),
                  UnsupportedFeatureWarning, stacklevel=3)


def warn_physical(source: str, element: str, problem: str, strict: bool,
                  error: type[DescriptionError] = InvalidInertiaError) -> None:
    """Warn about a non-physical but usable value, or raise ``error`` under ``strict``."""
    if strict:
        raise error(source, element, problem + " (refused under --strict)")
    warnings.warn(one_line(f"{source}: {element}: {problem}"), PhysicalConsistencyWarning,
                  stacklevel=3)
