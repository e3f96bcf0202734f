"""Frame kinematics of named links: pose, Jacobians and J̇ q̇, as a straight-line program.

For every frame ``f`` asked for (any link of the model: a body, or a frame fixed to one such as
a foot or a tool), :func:`derive_frames` builds, in the world frame: the frame of the model's
root link, or, when a scene moved the fixed frame (:attr:`RobotModel.root_pose
<eomgen.model.RobotModel.root_pose>`), the description's root link frame again:

* ``p_f`` (3×1): the frame origin [m] in world coordinates;
* ``R_f`` (3×3): the frame axes in world coordinates (``x_world = R_f x_f + p_f``);
* ``J_f`` (6×n), **world-aligned at the frame origin** (Pinocchio's ``LOCAL_WORLD_ALIGNED``):
  ``[ṗ_f; ω] = J_f q̇``, linear rows first, ω the angular velocity in world axes;
* ``Jb_f`` (6×n), **body** (Pinocchio's ``LOCAL``): ``[R_fᵀ ṗ_f; R_fᵀ ω] = Jb_f q̇``;
* ``dJqd_f`` (6×1), the world-aligned ``J̇ q̇``: the classical acceleration ``[p̈_f; ω̇]`` at
  ``q̈ = 0``, so that ``[p̈_f; ω̇] = J_f q̈ + dJqd_f``;
* ``dJbqd_f`` (6×1), the body ``J̇ q̇``: the time derivative of ``[v_b; ω_b] = Jb_f q̇`` at
  ``q̈ = 0``, i.e. ``[R_fᵀ p̈_f − ω_b × v_b; R_fᵀ ω̇]`` (the spatial body acceleration, which is
  what Pinocchio's ``CONTACT_6D`` constraint in ``LOCAL`` holds at zero).

Columns follow ``JOINT_NAMES`` order. The construction reuses the world-frame forward
kinematics of :mod:`eomgen.symbolic.composite`: joint i's motion axis ``S_i = [z_i; p_i × z_i]``
(angular first, referred to the world origin). A frame on body k moves with the joints on the
path from the root to k; its Jacobian column for such a joint is ``[S_lin + S_ang × p_f;
S_ang]``. With ``V_i = Σ_{j ⪯ i} S_j q̇_j`` the spatial velocity of body i, ``Ṡ_i = V_i × S_i``,
so the spatial acceleration bias is ``A = Σ_i (V_i × S_i) q̇_i`` and
``p̈_f = A_lin + A_ang × p_f + ω × ṗ_f`` at ``q̈ = 0``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Iterable

import sympy as sp

from ..errors import GenerationError
from ..model import POINT, RobotModel
from ..model.bodies import frame_site  # where a link sits on its body; importable here
from .builders import builds, provides
from .composite import forward_kinematics
from .derivation import new_derivation
from .evaluate import compile_program
from .charts import chart_offset
from .program import Program, ProgramBuilder
from .spatial import cross, matmul, matvec, motion_cross, transpose

if TYPE_CHECKING:  # the annotations only: NumPy is imported where it is used
    import numpy as np

#: The outputs of each frame, ``<kind>_<k>`` with k the frame's index in ``frames``.
FRAME_OUTPUTS = ("p", "R", "J", "Jb", "dJqd", "dJbqd")


@dataclass(frozen=True)
class FrameKinematics:
    """The frame kinematics of one model (see the module docstring). Immutable.

    Attributes
    ----------
    model:
        The model.
    frames:
        The frame (link) names, in the order of the outputs' index ``k``.
    q, qd:
        Joint position and velocity symbols, ``JOINT_NAMES`` order (with quaternion joints
        ``q`` is the configuration's, NQ symbols).
    program:
        Outputs ``p_k``, ``R_k``, ``J_k``, ``Jb_k``, ``dJqd_k``, ``dJbqd_k`` per frame k.
    """

    model: RobotModel
    frames: tuple[str, ...]
    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    program: Program

    def output(self, kind: str, frame: str) -> sp.Matrix:
        """The output ``kind`` (one of :data:`FRAME_OUTPUTS`) of ``frame``, in intermediates."""
        return self.program.output(f"{kind}_{self.frames.index(frame)}")

    @cached_property
    def _compiled(self):
        params = tuple(p.symbol for p in self.model.parameters)
        values = self.model.parameter_values
        missing = [p.name for p in self.model.parameters if p.symbol not in values]
        if missing:
            raise ValueError("no numeric value for parameters " + ", ".join(missing))
        f = compile_program(self.program, self.q + self.qd + params)
        tail = tuple(float(values[s]) for s in params)
        return lambda q, qd: f(*(float(x) for x in q), *(float(x) for x in qd), *tail)

    def evaluate(self, q, qd=None) -> dict[str, dict[str, np.ndarray]]:
        """Numbers at one state: ``{frame: {"p": (3,), "R": (3, 3), "J": (6, n), "Jb": (6, n),
        "dJqd": (6,), "dJbqd": (6,)}}``; parameters take their default values; ``qd``
        defaults to zero."""
        import numpy as np  # here: derive imports this module (F_c's size), not NumPy

        nq, nv = len(self.q), len(self.qd)  # NQ ≠ NV with quaternion joints
        q = np.asarray(q, dtype=float).reshape(nq)
        qd = np.zeros(nv) if qd is None else np.asarray(qd, dtype=float).reshape(nv)
        raw = self._compiled(q, qd)
        out = {}
        for k, name in enumerate(self.frames):
            out[name] = {kind: raw[f"{kind}_{k}"] for kind in FRAME_OUTPUTS}
            for kind in ("p", "dJqd", "dJbqd"):
                out[name][kind] = out[name][kind].reshape(-1)
        return out


def derive_frames(model: RobotModel, frames: Iterable[str] | None = None) -> FrameKinematics:
    """Derive pose, Jacobians and J̇ q̇ of the named links (all links by default).

    Raises
    ------
    KinematicTreeError
        For a name that is not a link of the model.
    """
    frames = tuple(frames) if frames is not None else tuple(l.name for l in model.links)
    d = new_derivation(model, ("q", "qd"))
    kinematics = frame_kinematics(model, d.tree, d.q, d.qd, d.builder, frames)
    outputs = [(f"{kind}_{k}", values[kind]) for k, values in enumerate(kinematics)
               for kind in FRAME_OUTPUTS]
    return FrameKinematics(model, frames, d.inputs["q"], d.qd, d.program(outputs))


def frame_kinematics(model: RobotModel, tree, q, qd, b: ProgramBuilder,
                     frames: tuple[str, ...]) -> list[dict[str, sp.Matrix]]:
    """For each of ``frames``, ``{kind: sympy.Matrix}`` for the kinds of :data:`FRAME_OUTPUTS`
    (module docstring; ``p`` and the J̇ q̇ are columns), in intermediates defined in ``b``."""
    sites = [frame_site(model, name) for name in frames]
    body_of = {body.joint.child: i for i, body in enumerate(tree.bodies)}
    n = model.dof
    kin = forward_kinematics(tree, q, b)
    result: list[dict[str, sp.Matrix]] = []
    velocity: dict[int, tuple] = {}  # body -> spatial velocity V_i (world origin)
    bias: dict[int, tuple] = {}      # body -> spatial acceleration at q̈ = 0

    def motion(i: int) -> tuple[tuple, tuple]:
        if i not in velocity:
            parent = tree.bodies[i].parent
            V0, A0 = motion(parent) if parent >= 0 else ((0,) * 6, (0,) * 6)
            rate = qd[tree.bodies[i].q_index]
            V = b.define_all(tuple(V0[r] + kin.S[i][r] * rate for r in range(6)), f"V{i + 1}_")
            VxS = motion_cross(V, kin.S[i])
            A = b.define_all(tuple(A0[r] + VxS[r] * rate for r in range(6)), f"Ab{i + 1}_")
            velocity[i], bias[i] = V, A
        return velocity[i], bias[i]

    for k, (name, (link, pose)) in enumerate(zip(frames, sites)):
        J = sp.zeros(6, n)
        if link is None:
            R = pose.rotation
            p = pose.translation
            dJqd = (0,) * 6
            w = v_lin = (0, 0, 0)
        else:
            i = body_of[link]
            R = tuple(b.define_all(row, f"Rf{k}_{r}") for r, row in
                      enumerate(matmul(kin.R[i], pose.rotation)))
            p = b.define_all(tuple(kin.p[i][r] + e for r, e in
                                   enumerate(matvec(kin.R[i], pose.translation))), f"pf{k}_")
            for j in [i] + tree.ancestors(i):
                S = kin.S[j]
                lin = b.define_all(tuple(S[3 + r] + e for r, e in
                                         enumerate(cross(S[:3], p))), f"Jf{k}_{j + 1}_")
                col = tree.bodies[j].q_index
                for r in range(3):
                    J[r, col] = lin[r]
                    J[3 + r, col] = S[r]
            V, A = motion(i)
            w = V[:3]
            v_lin = b.define_all(tuple(V[3 + r] + e for r, e in enumerate(cross(w, p))),
                                 f"vf{k}_")
            Axp = cross(A[:3], p)
            wxv = cross(w, v_lin)
            acc = b.define_all(tuple(A[3 + r] + Axp[r] + wxv[r] for r in range(3)), f"af{k}_")
            dJqd = tuple(acc) + tuple(A[:3])
            if any(o != 0 for o in kin.origin):  # kin.p is from the first joint's origin
                p = b.define_all(tuple(o + e for o, e in zip(kin.origin, p)), f"pof{k}_")
        Rt = transpose(R)
        Jb = sp.zeros(6, n)
        for col in range(n):
            for half in (0, 3):
                rotated = matvec(Rt, tuple(J[half + r, col] for r in range(3)))
                for r in range(3):
                    Jb[half + r, col] = b.define(rotated[r], f"Jb{k}_{half + r}_{col + 1}")
        w_b = b.define_all(matvec(Rt, w), f"wb{k}_")
        v_b = b.define_all(matvec(Rt, v_lin), f"vb{k}_")
        a_b = matvec(Rt, dJqd[:3])
        wxv_b = cross(w_b, v_b)
        dJbqd = (tuple(b.define(a_b[r] - wxv_b[r], f"ab{k}_{r}") for r in range(3))
                 + b.define_all(matvec(Rt, dJqd[3:]), f"wdb{k}_"))
        if model.root_pose is not None:  # to the description's root frame (Jb, dJbqd stay)
            R0, t0 = model.root_pose.rotation, model.root_pose.translation
            p = b.define_all(tuple(t0[r] + e for r, e in enumerate(matvec(R0, p))), f"pw{k}_")
            R = tuple(b.define_all(row, f"Rw{k}_{r}") for r, row in enumerate(matmul(R0, R)))
            Jw = sp.zeros(6, n)
            for col in range(n):
                for half in (0, 3):
                    rotated = matvec(R0, tuple(J[half + r, col] for r in range(3)))
                    for r in range(3):
                        Jw[half + r, col] = b.define(rotated[r], f"Jw{k}_{half + r}_{col + 1}")
            J = Jw
            dJqd = b.define_all(matvec(R0, dJqd[:3]) + matvec(R0, dJqd[3:]), f"dJw{k}_")
        if model.nq > model.dof:  # a chart: its J̇ q̇ less J n(v)
            dJqd = corrected_bias(model, J, dJqd, qd, b, f"dJff{k}_")
            dJbqd = corrected_bias(model, Jb, dJbqd, qd, b, f"dJbff{k}_")
        result.append({
            "p": sp.Matrix(3, 1, list(p)),
            "R": sp.Matrix(3, 3, [x for row in R for x in row]),
            "J": J,
            "Jb": Jb,
            "dJqd": sp.Matrix(6, 1, list(dJqd)),
            "dJbqd": sp.Matrix(6, 1, list(dJbqd)),
        })
    return result


def corrected_bias(model: RobotModel, J: sp.Matrix, bias, qd, b: ProgramBuilder,
                   hint: str) -> tuple:
    """``J̇ v`` of a model whose configuration is not its coordinates from the chart's:
    ``bias − J n(v)`` (:func:`eomgen.symbolic.charts.chart_offset`), named with ``hint``."""
    n = chart_offset(model, qd)
    return b.define_all(tuple(bias[r] - sp.Add(*[J[r, c] * n[c] for c in range(len(n))
                                                 if n[c] != 0])
                              for r in range(J.rows)), hint)


def output_frames(model: RobotModel) -> tuple[str, ...]:
    """The frames of the ``frame_*`` outputs, in the order of their blocks (``FRAME_NAMES``):
    the scene's ``frames:`` (:attr:`RobotModel.frames <eomgen.model.RobotModel.frames>`), else
    the frames of its contacts (first appearance), else every leaf link of the tree (a link no
    joint hangs from), in description order."""
    if model.frames:
        return tuple(model.frames)
    if model.contacts:
        return tuple(dict.fromkeys(c.frame for c in model.contacts))
    parents = {j.parent for j in model.joints}
    return tuple(l.name for l in model.links if l.name not in parents)


#: What each frame output stacks, by symbol: (kind of :data:`FRAME_OUTPUTS`, rows per frame).
FRAME_SYMBOLS = {"p_f": ("p", 3), "R_f": ("R", 3), "J_f": ("J", 6), "Jb_f": ("Jb", 6),
                 "dJqd_f": ("dJqd", 6), "dJbqd_f": ("dJbqd", 6)}


@builds("p_f", "R_f", "J_f", "Jb_f", "dJqd_f", "dJbqd_f")
def build_frames(derivation, wanted) -> dict:
    """The builder of the ``frame_*`` outputs (:mod:`eomgen.outputs`), stacked over the frames
    of :func:`output_frames` (``FRAME_NAMES`` order), frame k in rows ``k r … k r + r − 1``:

    * ``p_f`` (nf×3): row k the origin of frame k [m], world coordinates;
    * ``R_f`` (3 nf×3): block k its rotation (``x_world = R x_frame + p``);
    * ``J_f`` (6 nf×n): block k its world-aligned Jacobian at the frame origin, **linear rows
      first**: ``[ṗ; ω] = J q̇`` (Pinocchio's ``getFrameJacobian(..., LOCAL_WORLD_ALIGNED)``,
      whose rows are also ``[v; ω]``, when q̇ is Pinocchio's velocity);
    * ``Jb_f`` (6 nf×n): the body Jacobian ``[R ᵀṗ; Rᵀω]`` (Pinocchio's ``LOCAL``);
    * ``dJqd_f`` (6 nf,): ``J̇ q̇`` of ``J_f``, the classical acceleration ``[p̈; ω̇]`` at q̈ = 0;
    * ``dJbqd_f`` (6 nf,): ``J̇ q̇`` of ``Jb_f``, the time derivative of the body twist at q̈ = 0,
      ``[Rᵀp̈ − ω_b × v_b; Rᵀω̇]`` (Pinocchio's spatial ``getFrameAcceleration(..., LOCAL)`` at
      q̈ = 0).
    """
    frames = output_frames(derivation.model)
    kin = frame_kinematics(derivation.model, derivation.tree, derivation.q, derivation.qd,
                           derivation.builder, frames)
    result = {}
    for symbol in wanted:
        kind, _ = FRAME_SYMBOLS[symbol]
        blocks = [values[kind].T if kind == "p" else values[kind] for values in kin]
        result[symbol] = sp.Matrix.vstack(*blocks)
    return result


@provides("FRAME_NAMES")
def frame_constants(dynamics) -> dict[str, tuple[str, ...]]:
    """``FRAME_NAMES``: the frames of the ``frame_*`` outputs, in block order."""
    return {"FRAME_NAMES": output_frames(dynamics.model)}


def contact_rows(model: RobotModel) -> tuple[str, ...]:
    """Names of the rows of ``J_c`` and of ``F_c``: ``<contact>.f_x`` … (a point contact: force
    in world axes; a surface contact: force then moment ``n_x`` … in its frame's axes)."""

    rows = []
    for c in model.contacts:
        axes = ("f_x", "f_y", "f_z") if c.kind == POINT else (
            "f_x", "f_y", "f_z", "n_x", "n_y", "n_z")
        rows += [f"{c.name}.{a}" for a in axes]
    return tuple(rows)


def contact_row_count(model: RobotModel) -> int:
    """m, the length of ``F_c`` and the rows of ``J_c``: 3 per point contact, 6 per surface
    contact (0 without contacts)."""
    return len(contact_rows(model))


def _require_contacts(model: RobotModel) -> None:
    if not model.contacts:
        raise GenerationError(
            f"{model.source}: contact outputs (contact_jacobian, contact_bias, "
            f"constrained_forward_dynamics, contact_inverse_dynamics, friction cone margins) "
            f"need contacts, and robot '{model.name}' has none: declare them in a scene "
            "(contacts: [{frame: <link>}])")


def build_contacts(derivation, wanted) -> dict:
    """The builder of ``J_c`` (m×n) and ``dJqd_c`` (``J̇_c q̇``, (m,)): the rows of the model's
    contacts as :class:`eomgen.numeric.contacts.ContactDynamics` stacks them, in contact order. A
    point contact gives the linear rows of the world-aligned frame Jacobian (its force in world
    axes); a surface contact the six rows of the body Jacobian (its wrench in the frame's
    axes). Baumgarte gains are not part of these rows.

    Raises
    ------
    GenerationError
        When the model carries no contacts (a scene's ``contacts:``).
    """

    model = derivation.model
    _require_contacts(model)
    frames = tuple(dict.fromkeys(c.frame for c in model.contacts))
    kin = frame_kinematics(model, derivation.tree, derivation.q, derivation.qd,
                           derivation.builder, frames)
    J, bias = [], []
    for c in model.contacts:
        values = kin[frames.index(c.frame)]
        if c.kind == POINT:
            J.append(values["J"][:3, :])
            bias.append(values["dJqd"][:3, :])
        else:
            J.append(values["Jb"])
            bias.append(values["dJbqd"])
    result = {"J_c": sp.Matrix.vstack(*J), "dJqd_c": sp.Matrix.vstack(*bias)}
    return {k: v for k, v in result.items() if k in wanted}


@builds("tau_c")
def build_contact_inverse_dynamics(derivation, wanted) -> dict:
    """The builder of ``tau_c`` (n,): the joint efforts ``τ = M q̈ + C q̇ + g − J_cᵀ F_c`` that
    give the accelerations ``q̈`` while the contacts push on the robot with ``F_c`` (rows
    ``CONTACT_ROWS``, in the axes of :func:`build_contacts`' rows: a point contact's force in
    world axes at the frame origin, a surface contact's force and moment in the frame's axes).
    It reuses the Newton–Euler ``tau`` and ``J_c`` already in the program (with loops, ``J_c``
    and ``F_c`` hold their rows too: :mod:`eomgen.symbolic.loops`)."""
    if not derivation.model.loops:
        _require_contacts(derivation.model)
    tau = derivation.output("tau")
    J = derivation.output("J_c")
    F = sp.Matrix(derivation.inputs["F_c"])
    return {"tau_c": tau - J.T * F}


def _friction_contacts(model: RobotModel) -> list:
    """``(contact, first row, unit normal in the axes of its force rows)`` of every contact,
    refusing contacts without a friction coefficient."""

    _require_contacts(model)
    missing = [c.name for c in model.contacts if c.mu is None]
    if missing:
        raise GenerationError(
            f"{model.source}: contact '{missing[0]}' has no friction coefficient: the friction "
            "cone outputs need 'mu' on every contact of the scene")
    import numpy as np  # here: derive imports this module (F_c's size), not NumPy

    out, row = [], 0
    for c in model.contacts:
        normal = np.asarray(c.normal if c.kind == POINT else (0.0, 0.0, 1.0), dtype=float)
        out.append((c, row, normal / np.linalg.norm(normal)))
        row += c.size
    return out


def _tangents(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit tangents ``t1, t2`` with ``(t1, t2, normal)`` right-handed: ``t1`` is the
    coordinate axis least aligned with the normal, made orthogonal to it."""
    import numpy as np  # here: derive imports this module (F_c's size), not NumPy

    axis = np.eye(3)[int(np.argmin(np.abs(normal)))]
    t1 = axis - (axis @ normal) * normal
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(normal, t1)


def _exact(x: float):
    """``x`` as a SymPy number: an integer when it is one (so that 0 drops out), else the
    float."""
    return sp.Integer(int(x)) if float(x).is_integer() else sp.Float(float(x))


@builds("cone_c", "pyramid_c")
def build_friction_cones(derivation, wanted) -> dict:
    """The builders of the friction-cone margins of the contact forces ``F_c`` (rows
    ``CONTACT_ROWS``), one friction coefficient μ per contact (the scene's ``mu``):

    * ``cone_c`` (nc,), the exact (second-order) cone: ``μ f_n − ‖f_t‖`` [N] per contact, with
      ``f_n = f · n`` and ``f_t = f − f_n n``; ``≥ 0`` inside the cone (a pulling contact,
      ``f_n < 0``, is outside);
    * ``pyramid_c`` (4 nc,), the inscribed four-sided pyramid, linear in ``F_c`` (what a QP
      takes): for each contact ``μ/√2 f_n − f_t1``, ``μ/√2 f_n + f_t1``, ``μ/√2 f_n − f_t2``,
      ``μ/√2 f_n + f_t2`` [N], all ``≥ 0`` inside. Inside the pyramid implies inside the cone.

    The normal ``n`` is a point contact's ``normal`` (world axes, like its force) or a surface
    contact's frame +z axis (its force rows are in frame axes); ``f`` is the force part of the
    contact's rows (a surface contact's moment is not checked). The tangents ``t1, t2`` complete
    ``n`` to a right-handed frame, ``t1`` from the coordinate axis least aligned with ``n``
    (for ``n = +z``: ``t1 = x``, ``t2 = y``).
    """
    import numpy as np  # here: derive imports this module (F_c's size), not NumPy

    F = derivation.inputs["F_c"]
    cone, pyramid = [], []
    for c, row, normal in _friction_contacts(derivation.model):
        f = F[row:row + 3]
        t1, t2 = _tangents(normal)
        fn = sum(_exact(a) * x for a, x in zip(normal, f))
        ft1 = sum(_exact(a) * x for a, x in zip(t1, f))
        ft2 = sum(_exact(a) * x for a, x in zip(t2, f))
        mu = _exact(c.mu)
        cone.append(mu * fn - sp.sqrt(ft1 ** 2 + ft2 ** 2))
        k = _exact(c.mu / np.sqrt(2))
        pyramid += [k * fn - ft1, k * fn + ft1, k * fn - ft2, k * fn + ft2]
    result = {"cone_c": sp.Matrix(cone), "pyramid_c": sp.Matrix(pyramid)}
    return {k: v for k, v in result.items() if k in wanted}


@provides("CONTACT_NAMES", "PYRAMID_ROWS")
def pyramid_constants(dynamics) -> dict[str, tuple[str, ...]]:
    """``CONTACT_NAMES`` and ``PYRAMID_ROWS``, the rows of ``friction_pyramid_margins``:
    ``<contact>.-t1``, ``<contact>.+t1``, ``<contact>.-t2``, ``<contact>.+t2``."""
    names = tuple(c.name for c in dynamics.model.contacts)
    return {"CONTACT_NAMES": names,
            "PYRAMID_ROWS": tuple(f"{name}.{side}" for name in names
                                  for side in ("-t1", "+t1", "-t2", "+t2"))}


def contact_constants(dynamics) -> dict[str, tuple[str, ...]]:
    """``CONTACT_NAMES`` (the contacts, in order) and ``CONTACT_ROWS`` (:func:`contact_rows`)."""
    model = dynamics.model
    return {"CONTACT_NAMES": tuple(c.name for c in model.contacts),
            "CONTACT_ROWS": contact_rows(model)}


__all__ = ["FRAME_OUTPUTS", "FRAME_SYMBOLS", "FrameKinematics", "derive_frames", "frame_site",
           "frame_kinematics", "output_frames", "build_frames", "frame_constants", "contact_rows",
           "build_contacts", "contact_constants", "contact_row_count", "build_contact_inverse_dynamics",
           "build_friction_cones", "pyramid_constants"]
