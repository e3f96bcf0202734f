"""A model's loops checked against its mechanism, numerically (:func:`check_loops`), when the
model is built: a scene applied (:func:`eomgen.reduction.apply_scene`), an MJCF file read.

The rows of each loop (:mod:`eomgen.symbolic.loops`: translations along world axes or a planar
loop's in-plane axes ``u, v``, a weld's rotations, a hinge's two rotations about the axes of
frame a normal to its axis) are built again here from the float frame recursion
(:mod:`eomgen.numeric.frames`), at :data:`SAMPLES` random configurations (seeded: the same
answer every time), and the model is refused (:class:`LoopProblem`, which the callers turn
into a one-line error naming the file and the loop) when

* its two frames are on one rigid body (:func:`eomgen.model.bodies.frame_site`), or no row of
  it moves: every joint moves its two frames together (frames on bodies welded
  to each other, or joined only through joints about the loop's point) — it constrains
  nothing;
* a planar loop's plane does not hold the motion: the rows it leaves out (the relative
  translation along its normal ``n``; for a hinge or a weld the relative rotation about the
  in-plane axes) are not identically zero — a joint between the two frames moves them out of
  the plane (the plane is not the mechanism's, a tilted axis, a free base that turns out of
  it) — or one of its rows never moves (the plane is not the mechanism's either);
* the loops leave no degree of freedom, or fewer than the coordinates named in ``actuated:``:
  ``n − rank J_l`` at a configuration where the loops are closed (Newton's method on ``Φ``
  over every coordinate, from the neutral configuration then random ones; at a random
  configuration when none closes them), the loop named being the first (in order) after
  which too few are left.

A spatial loop's rows that no joint moves (the out-of-plane rows of a planar mechanism closed
by a spatial loop, every MJCF loop of a planar model) are dependent rows, not an error: the
damped KKT solve handles them (docs/loops.md, "Redundant loops"); :class:`LoopMobility` says
which they are, and how many degrees of freedom the loops leave.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..model import HINGE, POINT_LOOP, WELD, RobotModel
from ..model.bodies import frame_site
from ..model.configuration import integrate, neutral
from ..model.loop import Loop, in_plane_axes
from .frames import frame_kinematics
from .model import numeric_model

#: Random configurations at which the rows are evaluated.
SAMPLES = 4
#: A row "moves" when some entry exceeds this fraction of the largest entry of every loop's
#: rows (and 1e-12 absolutely); a dropped row is zero below it.
ZERO_ROW = 1e-9
#: Singular values below this fraction of the largest count as zero in the rank.
RANK_TOLERANCE = 1e-8
#: |Φ|∞ [m, rad] at which the loops count as closed, and Newton's iterations per start.
CLOSED, ITERATIONS = 1e-10, 15
#: Closed configurations sought near the first one (random moves, closed again).
MOVES = 2


class LoopProblem(ValueError):
    """What is wrong with loop ``index`` of the model (``problem``: words, no file name)."""

    def __init__(self, index: int, problem: str):
        super().__init__(problem)
        self.index, self.problem = index, problem


@dataclass(frozen=True)
class LoopMobility:
    """What the loops leave of the mechanism.

    Attributes
    ----------
    coordinates:
        ``n``, the velocity coordinates (NV).
    rows:
        ``m``, the loops' rows.
    rank:
        The rank of ``J_l`` where the loops are closed (``closed``: the largest over a few
        closed configurations, as one may be singular), else at random configurations.
    closed:
        Whether Newton's method closed the loops (``|Φ|∞ ≤`` :data:`CLOSED`).
    still:
        The rows no joint moves (spatial loops only: dependent rows).
    """

    coordinates: int
    rows: int
    rank: int
    closed: bool
    still: tuple[str, ...] = ()

    @property
    def dof(self) -> int:
        """The degrees of freedom the loops leave, ``n − rank J_l``."""
        return self.coordinates - self.rank

    def counts(self) -> str:
        """``"3 coordinates, 2 of the 2 loop rows independent at a closed configuration"``."""
        where = ("at a closed configuration" if self.closed else "at a random configuration: "
                 "Newton's method did not close the loops")
        return (f"{self.coordinates} coordinates, {self.rank} of the {self.rows} loop rows "
                f"independent {where}")

    def describe(self) -> str:
        """One sentence: the degrees of freedom, and the dependent rows if any."""
        text = (f"the loops leave {_freedom(self.dof)} ({self.counts()})")
        if self.still:
            text += (f"; rows no joint moves (dependent: constrained_forward_dynamics needs "
                     f"damping > 0, or declare the loop planar): {', '.join(self.still)}")
        return text


def check_loops(model: RobotModel, seed: int = 0) -> LoopMobility:
    """Check ``model``'s loops against its joints (module docstring) and count the degrees
    of freedom they leave; ``model.actuated`` are the joints the scene drives.

    Raises
    ------
    LoopProblem
        Naming the loop (its index in ``model.loops``) and what is wrong.
    """
    for k, loop in enumerate(model.loops):
        body_a, body_b = (frame_site(model, f.link)[0] for f in (loop.a, loop.b))
        if body_a == body_b:
            body = f"'{body_a}'" if body_a is not None else "the world (fixed base)"
            raise LoopProblem(k, f"frames a (link '{loop.a.link}') and b (link "
                              f"'{loop.b.link}') are on the same rigid body {body}: the loop "
                              "constrains nothing")
    rng = np.random.default_rng(seed)
    rows = LoopRows(model)
    samples = [rows.at(_random(model, rng)) for _ in range(SAMPLES)]
    J = np.stack([s[1] for s in samples])               # (samples, m, n)
    scale = max(float(np.abs(J).max(initial=0.0)), 1.0)
    still = []
    for k, loop in enumerate(model.loops):
        mine = J[:, rows.slices[k], :]
        moving = [np.abs(mine[:, r, :]).max() > ZERO_ROW * scale for r in range(loop.size)]
        if not any(moving):
            raise LoopProblem(k, f"no joint moves frame b (link '{loop.b.link}') relative to "
                              f"frame a (link '{loop.a.link}') along any of its rows "
                              f"({', '.join(loop.rows)}): the loop constrains nothing (the two "
                              "frames are rigidly joined, or only by joints about its point)")
        if loop.plane is not None:
            _check_plane(k, loop, np.stack([s[2][k] for s in samples]), scale)
            if not all(moving):
                row = loop.rows[moving.index(False)]
                raise LoopProblem(k, f"no joint moves its row {row} (plane normal "
                                  f"{_vector(loop.plane)}): the mechanism does not move in "
                                  "that plane")
        else:
            still += [name for name, m in zip(loop.rows, moving) if not m]
    closed = _closed(model, rows, rng)
    at = [rows.at(q)[1] for q in closed] or [s[1] for s in samples]

    def rank(stop: int) -> int:  # the generic rank: the largest over the configurations
        return max(_rank(J[:stop]) for J in at)

    mobility = LoopMobility(model.dof, rows.size, rank(rows.size), bool(closed), tuple(still))
    wanted = len(model.actuated)
    for k, loop in enumerate(model.loops):
        left = model.dof - rank(rows.slices[k].stop)
        if left <= 0:
            raise LoopProblem(k, f"the loops leave no degree of freedom ({mobility.counts()}): "
                              "the mechanism is rigid")
        if left < wanted:
            raise LoopProblem(k, f"the loops leave {_freedom(left)}, fewer than the {wanted} "
                              f"coordinates named in actuated ({', '.join(model.actuated)}; "
                              f"{mobility.counts()}): the actuated joints cannot all be "
                              "driven; name at most " + str(left))
    return mobility


def _check_plane(k: int, loop: Loop, dropped: np.ndarray, scale: float) -> None:
    """Refuse a planar loop whose left-out rows (``dropped``: samples × rows × n) move."""
    worst = np.abs(dropped).max(axis=(0, 2))
    if worst.max(initial=0.0) <= ZERO_ROW * scale:
        return
    what = ("moves its frames apart along the normal" if worst[0] > ZERO_ROW * scale else
            "turns its frames relative to each other about an in-plane axis")
    raise LoopProblem(k, f"the plane (normal {_vector(loop.plane)}, world axes) does not hold "
                      f"the motion: a joint between its frames {what} (largest rate "
                      f"{worst.max():.3g} per unit joint rate); the joints between them must "
                      "keep both frames in that plane (a plane that is not the mechanism's, a "
                      "tilted joint axis, a free base that turns out of the plane): give the "
                      "mechanism's normal, or declare the loop spatial")


class LoopRows:
    """The loops' rows ``Φ`` and ``J_l`` at a configuration, and the rows a planar loop
    leaves out, from :func:`eomgen.numeric.frames.frame_kinematics`."""

    def __init__(self, model: RobotModel):
        self.model, self.nm = model, numeric_model(model)
        values = model.parameter_values
        self.links = tuple(dict.fromkeys(f.link for loop in model.loops for f in (loop.a, loop.b)))
        self.poses = [tuple(_pose(f.pose, values) for f in (loop.a, loop.b))
                      for loop in model.loops]
        self.slices, start = [], 0
        for loop in model.loops:
            self.slices.append(slice(start, start + loop.size))
            start += loop.size
        self.size = start

    def at(self, q) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
        """``(Φ (m,), J_l (m, n), [the left-out rows of each loop (·, n)])`` at ``q`` (NQ)."""
        kin = frame_kinematics(self.nm, q, frames=self.links)
        Phi, J, dropped = [], [], []
        for loop, (pa, pb) in zip(self.model.loops, self.poses):
            A, B = (_frame(kin[f.link], pose) for f, pose in ((loop.a, pa), (loop.b, pb)))
            dp, dJ = B[0] - A[0], B[2] - A[2]         # relative position, rates (6, n)
            n = None if loop.plane is None else np.array(loop.plane, dtype=float)
            n = None if n is None else n / np.linalg.norm(n)
            E = np.eye(3) if n is None else np.array(in_plane_axes(n))
            Phi += list(E @ dp)
            J += list(E @ dJ[:3])
            left = [] if n is None else [n @ dJ[:3]]
            if loop.kind == WELD:
                half = 0.5 * sum(np.cross(A[1][:, c], B[1][:, c]) for c in range(3))
                W = np.eye(3) if n is None else n[None, :]
                Phi += list(W @ half)
                J += list(W @ dJ[3:])
            elif loop.kind == HINGE and n is None:
                axis = np.array(loop.axis, dtype=float)
                kxk = np.cross(A[1] @ axis, B[1] @ axis)
                for t in in_plane_axes(axis):
                    u = A[1] @ np.array(t)
                    Phi.append(u @ kxk)
                    J.append(u @ dJ[3:])
            if n is not None and loop.kind != POINT_LOOP:
                left += list(np.array(in_plane_axes(n)) @ dJ[3:])
            dropped.append(np.array(left))
        return np.array(Phi), np.array(J).reshape(len(Phi), self.model.dof), dropped


def _frame(kin: dict, pose) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(p, R, J)`` of the frame at ``pose = (R_f, t_f)`` in a link: origin, axes and
    world-aligned Jacobian (6, n) at the origin."""
    R_f, t_f = pose
    r = kin["R"] @ t_f
    J = kin["J"].copy()
    J[:3] -= np.cross(r[:, None], J[3:], axis=0)       # v = v_link + ω × r
    return kin["p"] + r, kin["R"] @ R_f, J


def _pose(transform, values) -> tuple[np.ndarray, np.ndarray]:
    def number(x):
        return float(sp.sympify(x).subs(values)) if isinstance(x, sp.Basic) else float(x)
    return (np.array([[number(x) for x in row] for row in transform.rotation]),
            np.array([number(x) for x in transform.translation]))


def _random(model: RobotModel, rng) -> np.ndarray:
    """A configuration (NQ) whose coordinates are uniform in [−π, π] from the neutral one."""
    return integrate(neutral(model), rng.uniform(-np.pi, np.pi, model.dof), 1.0, model)


def _closed(model: RobotModel, rows: LoopRows, rng) -> list[np.ndarray]:
    """Configurations where the loops close: Newton's least-norm steps over every coordinate
    from the neutral configuration then from random ones until one closes, then from
    :data:`MOVES` random moves away from it (a start may close at a singular
    configuration: the rank is the largest over them); empty when none closes."""
    starts = [neutral(model)] + [_random(model, rng) for _ in range(SAMPLES)]
    for start in starts:
        q = _newton(model, rows, start)
        if q is not None:
            break
    else:
        return []
    found = [q]
    for _ in range(MOVES):
        q = _newton(model, rows, integrate(found[0], rng.normal(0.0, 0.5, model.dof), 1.0,
                                           model))
        if q is not None:
            found.append(q)
    return found


def _newton(model: RobotModel, rows: LoopRows, q) -> np.ndarray | None:
    for _ in range(ITERATIONS):
        Phi, J, _ = rows.at(q)
        if np.abs(Phi).max(initial=0.0) <= CLOSED:
            return q
        q = integrate(q, -np.linalg.lstsq(J, Phi, rcond=None)[0], 1.0, model)
        if not np.all(np.isfinite(q)):
            return None
    return None


def _rank(J: np.ndarray) -> int:
    if J.size == 0:
        return 0
    sv = np.linalg.svd(J, compute_uv=False)
    return int(np.sum(sv > RANK_TOLERANCE * max(sv.max(), 1e-300)))


def _freedom(n: int) -> str:
    return f"{n} degree{'s' * (n != 1)} of freedom"


def _vector(v) -> str:
    return "(" + ", ".join(f"{float(x):.6g}" for x in v) + ")"


__all__ = ["LoopMobility", "LoopProblem", "LoopRows", "SAMPLES", "check_loops"]
