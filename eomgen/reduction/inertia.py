"""Inertial data of merged bodies, kept exact: parts combined about a body's origin, turned back
into mass, centre of mass and inertia, with numbers within roundoff (:data:`ROUNDOFF`) of 0 or ±1
snapped exact, as the reduction (:mod:`eomgen.reduction`) needs them."""

from __future__ import annotations

from typing import Iterable

import sympy as sp

from ..model.bodies import InertialParameters, merged_inertial
from ..model import ZERO3, Inertial, Transform, scalar

#: Relative size below which a number computed while merging is roundoff of an exact zero.
ROUNDOFF = 1e-13


def substituted_inertial(inertial: Inertial, values: dict) -> Inertial:
    if not values:
        return inertial

    def s(x):
        return scalar(x.xreplace({k: scalar(v) for k, v in values.items()}))

    return Inertial(s(inertial.mass), tuple(s(c) for c in inertial.com),
                    tuple(tuple(s(v) for v in row) for row in inertial.inertia))


def inertial_scalars(inertial: Inertial) -> Iterable[sp.Expr]:
    yield inertial.mass
    yield from inertial.com
    for row in inertial.inertia:
        yield from row


def is_zero_inertial(inertial: Inertial) -> bool:
    return all(x == 0 for x in inertial_scalars(inertial))


def _number(x) -> float | None:
    if isinstance(x, sp.Basic) and x.is_number:
        return float(x)
    return None


def clean_transform(T: Transform) -> Transform:
    """``T`` with rotation entries within roundoff (:data:`ROUNDOFF`) of 0 or ±1 made exact."""
    def snap_rotation(x):
        v = _number(x)
        if v is None:
            return x
        for target in (0, 1, -1):
            if abs(v - target) <= ROUNDOFF:
                return sp.Integer(target)
        return x

    rotation = tuple(tuple(snap_rotation(x) for x in row) for row in T.rotation)
    return Transform(rotation, T.translation)  # type: ignore[arg-type]


def combined_inertial(parts: list[tuple[Inertial, Transform]]) -> Inertial | None:
    """One body's inertial data from parts given in frames with the given poses."""
    if not parts:
        return None
    if len(parts) == 1 and parts[0][1] == Transform():
        return parts[0][0]
    return _inertial(merged_inertial(parts))


def _inertial(p: InertialParameters) -> Inertial | None:
    """Mass, centre of mass and inertia about it from inertial parameters about the origin."""
    m = p.mass
    if p.is_zero:
        return None
    if m == 0:
        return Inertial(0, ZERO3, p.inertia)
    com = tuple(tidy(h / m, abs_terms=[h]) for h in p.first_moment)
    cc = sum((c * c for c in com), sp.Integer(0))
    inertia = [[sp.Integer(0)] * 3 for _ in range(3)]
    for a in range(3):
        for b in range(a, 3):  # the upper triangle, mirrored: exactly symmetric
            shift = m * ((cc if a == b else 0) - com[a] * com[b])
            inertia[a][b] = inertia[b][a] = tidy(p.inertia[a][b] - shift,
                                                  abs_terms=[p.inertia[a][b], shift])
    return Inertial(scalar(m), com, tuple(tuple(row) for row in inertia))


def tidy(x, abs_terms) -> sp.Expr:
    """``x`` as a model scalar; an exact zero when it is roundoff of the ``abs_terms``."""
    v = _number(x)
    if v is None:
        return x
    scale = sum(abs(_number(t) or 0.0) for t in abs_terms)
    if abs(v) <= ROUNDOFF * scale:
        return sp.Integer(0)
    return scalar(v)


def scaled_inertial(inertial: Inertial, factor) -> Inertial:
    """``inertial`` with its mass and inertia times ``factor`` (its centre of mass kept): the
    weight a gravity compensation of that factor pushes back up."""
    return Inertial(factor * inertial.mass, inertial.com,
                    tuple(tuple(factor * x for x in row) for row in inertial.inertia))


def merged_gravcomp(model, site, parts, bodies) -> tuple:
    """:attr:`~eomgen.model.RobotModel.gravcomp` of the bodies a scene merges: per moving body
    (``site``: each link's body and pose, :func:`eomgen.model.bodies.attach_fixed_links`;
    ``parts``: each body's inertial parts, payloads included; ``bodies``: ``(body, link)`` in
    the reduced model's order), its links' compensation added up. The compensation
    ``Σ γ_i m_i J_iᵀ (−g)`` is linear in each part's ``γ_i m_i`` and ``γ_i m_i c_i``, so it
    is exact as:

    * ``(link, γ)`` when every part with mass is compensated by one factor ``γ`` (the merged
      body's own inertial times it);
    * ``(link, 1, inertial)`` otherwise, ``inertial`` the parts' ``γ_i``-scaled inertials
      combined (parts of different factors, a payload the compensation does not hold up).

    Links fixed to the world (no joint force) are left out."""
    if not model.gravcomp:
        return ()
    weighed: dict[int, list] = {}
    for entry in model.gravcomp:
        name, factor = entry[0], scalar(entry[1])
        inertial = entry[2] if len(entry) > 2 else model.link_by_name[name].inertial
        body, pose = site[name]
        if body >= 0 and inertial is not None and factor != 0 and inertial.mass != 0:
            weighed.setdefault(body, []).append((factor, inertial, pose, len(entry) > 2))
    out = []
    for body, link in bodies:
        found = weighed.get(body)
        if not found:
            continue
        massive = [p for p in parts[body] if p[0].mass != 0]
        if (len({f for f, *_ in found}) == 1 and len(found) == len(massive)
                and not any(own for *_, own in found)):
            out.append((link, found[0][0]))
        else:
            out.append((link, sp.Integer(1),
                        combined_inertial([(scaled_inertial(i, f), pose)
                                           for f, i, pose, _ in found])))
    return tuple(out)
