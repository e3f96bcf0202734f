"""Parsers: one ``load(path, strict, defer_notices) -> RobotModel`` per input format, in a
registry.

A format registers itself with :func:`register`, naming the file suffixes it reads and, for
YAML files shared by several formats, a ``sniff`` function that recognises its content. Adding a
format touches no other module.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from ..common.reading import not_regular
from ..errors import TooLargeError, UnknownFormatError, UnreadableFileError, closest_name
from ..model import Notice, NoticeKind, RobotModel, emit_notices, settled, snapping, uncoupled
from ..robots import EXAMPLES
from .registry import FORMATS, Format, Loader, register  # noqa: F401  (the formats' registry)


MAX_FILE_BYTES = 50 * 1024 * 1024


def load(path, strict: bool = False, defer_notices: bool = False,
         snap: bool = True, couplings: bool = True) -> RobotModel:
    """Read a robot description: URDF (``.urdf``), MuJoCo MJCF (``.xml`` with a ``<mujoco>``
    root, read by MuJoCo's compiler: :mod:`eomgen.parsers.mjcf`), DH table (``.yaml`` with
    ``dh:``) or eomgen YAML (``.yaml`` with ``links:``/``joints:``).

    Parameters
    ----------
    path:
        The description file, or the name of a bundled example (:data:`eomgen.robots.EXAMPLES`,
        e.g. ``"elbow_rrr"``; a file of that name wins), as the commands take it. A missing
        file's error suggests a close name (:func:`near_miss`).
    strict:
        Refuse (rather than warn about) inertias that break the triangle inequality, joints
        that move no mass (:mod:`eomgen.model.moving_mass`) and
        features read in a simpler way than described (a URDF root that looks like a floating
        base; followers read as independent joints with ``couplings=False``).
    defer_notices:
        Neither warn nor refuse yet: record these findings in the model's ``notices``
        (:class:`~eomgen.model.Notice`) for the caller to emit once it knows which still
        matter, e.g. after a scene (:func:`eomgen.reduction.load_for_scene`).
    snap:
        Make rotation and axis entries within :data:`~eomgen.model.SNAP_TOLERANCE` of 0 or ±1
        exact (structural zeros, shorter code); ``False`` keeps the description's floats
        exactly. The entries snapped are listed in ``model.info`` under ``"snapped"``
        (:class:`~eomgen.model.Snap`: what, value, target; see
        :func:`~eomgen.model.snap_summary`).
    couplings:
        Honour the description's coupled joints (URDF ``<mimic>``: the follower is no
        coordinate, :mod:`eomgen.model.coupling`). ``False`` reads every follower as an
        independent joint, with one notice (a warning) per follower saying so.

    Raises
    ------
    DescriptionError
        Naming the file, the element and what is wrong; a subclass for each kind of problem
        (see :mod:`eomgen.errors`): here :class:`~eomgen.errors.UnreadableFileError`,
        :class:`~eomgen.errors.UnknownFormatError` and :class:`~eomgen.errors.TooLargeError`
        (files above :data:`MAX_FILE_BYTES`), the others from the format's parser.
    """
    # Importing a format registers it; here, so that each parser and its dependencies load on
    # first use (start-up time), not with eomgen.parsers.
    from . import dh, mjcf, urdf, yaml_format  # noqa: F401

    path = Path(path)
    if not path.exists() and str(path) in EXAMPLES:
        path = EXAMPLES[str(path)]
    problem = not_regular(path)
    if problem is not None:
        hint = near_miss(path) if problem == "no such file" else ""
        raise UnreadableFileError(str(path), "", problem + hint)
    if path.stat().st_size > MAX_FILE_BYTES:
        raise TooLargeError(str(path), "", f"file larger than {MAX_FILE_BYTES} bytes")
    suffix = path.suffix.lower()
    candidates = [f for f in FORMATS if suffix in f.suffixes]
    if not candidates:
        known = sorted({s for f in FORMATS for s in f.suffixes})
        raise UnknownFormatError(str(path), "", f"unknown file type '{suffix}' (known: {', '.join(known)})")
    if len(candidates) > 1:
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError as exc:
            raise UnreadableFileError(str(path), "", f"not UTF-8 text ({exc.reason})") from None
        except OSError as exc:
            raise UnreadableFileError(str(path), "",
                                      f"cannot read the file ({exc.strerror})") from None
        sniffed = [f for f in candidates if f.sniff is None or f.sniff(text)]
        if len(sniffed) != 1:
            raise UnknownFormatError(
                str(path), "",
                "cannot tell which format this is (" + " or ".join(f.name for f in candidates)
                + "): a DH table needs a top-level 'dh' list, an eomgen robot 'links' and 'joints'")
        candidates = sniffed
    with snapping(snap) as snaps:
        model = candidates[0].load(path, strict, defer_notices=True)
    if snaps:
        model = replace(model, info=model.info + (("snapped", tuple(snaps)),))
    if not couplings and model.couplings:
        model = independent_followers(model, strict, defer_notices=True)
    model = settled(model)  # the whole model known: what its masses leave to say
    if not defer_notices:
        emit_notices(model.notices, strict)
    return model


#: At most this many names of a folder are compared with a missing file's (:func:`near_miss`).
NEAR_MISS_SCAN = 2000


def near_miss(path: Path) -> str:
    """``"; did you mean 'x'?"`` for a missing description ``path``: the closest name among the
    files beside it and, for a bare name, the bundled examples (:data:`eomgen.robots.EXAMPLES`,
    which commands take by name); empty when none is close."""
    known: dict[str, str] = {}  # the name compared → what to suggest
    try:
        for _, entry in zip(range(NEAR_MISS_SCAN), (path.parent or Path(".")).iterdir()):
            if entry.is_file():
                known[entry.name] = str(path.with_name(entry.name))
    except OSError:
        pass
    if path.parent == Path("."):
        known.update({name: name for name in EXAMPLES})
    hint = closest_name(path.name, known)
    return f"; did you mean '{known[hint]}'?" if hint else ""


def independent_followers(model: RobotModel, strict: bool = False,
                          defer_notices: bool = False, how: str = "couplings=False"
                          ) -> RobotModel:
    """``model`` with its followers read as independent joints, one
    :attr:`~eomgen.model.NoticeKind.MIMIC` notice per follower (warned, refused under
    ``strict``, or kept in ``model.notices`` with ``defer_notices``); ``how`` names what asked
    for it in the notices."""
    found = tuple(
        Notice(NoticeKind.MIMIC, model.source, c.where,
               f"the coupling to joint{'s' if len(c.leaders) > 1 else ''} "
               + ", ".join(f"'{name}'" for name, _ in c.leaders) + " is not modelled",
               f"read as an independent joint ({how})",
               joints=(c.follower,) + tuple(name for name, _ in c.leaders))
        for c in model.couplings)
    if not defer_notices:
        emit_notices(found, strict)
    return replace(uncoupled(model), notices=model.notices + found)
