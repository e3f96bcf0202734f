"""Rigid contacts, numerically: ``M q̈ + C q̇ + g = τ + J_cᵀ F_c`` with ``J_c q̈ + J̇_c q̇ = −γ``.

A :class:`~eomgen.model.Contact` (plain data of the model layer) holds a named frame (a link, see
:mod:`eomgen.symbolic.frames`) still:

* a **point** contact (3 rows) holds the frame origin: ``p̈_f = 0``. Its rows of ``J_c`` are
  the linear rows of the world-aligned frame Jacobian, and its force ``F = (f_x, f_y, f_z)``
  [N] acts on the robot at the frame origin, in **world** axes (Pinocchio's ``CONTACT_3D``
  with ``LOCAL_WORLD_ALIGNED``). Its ``normal`` is a unit vector in world axes (default +z).
* a **surface** contact (6 rows) holds the whole frame: the body twist ``[v_b; ω_b]`` stays
  zero. Its rows are the body (``LOCAL``) Jacobian, its wrench ``F = (f, n)`` [N, N m] acts
  at the frame origin in the **frame's** axes (Pinocchio's ``CONTACT_6D`` in ``LOCAL``), and
  the contact normal is the frame's +z axis.

Baumgarte stabilisation (optional gains ``kd`` [1/s], ``kp`` [1/s²]) adds
``γ = kd J q̇ + kp e`` to the constraint, so that the constraint error obeys
``ë + kd ė + kp e = 0`` (to first order in ``e``). The error ``e``:

* point contact: ``e = p − p*`` [m], world axes, ``p*`` its ``anchors[frame]`` (none: no
  position term);
* surface contact: ``e = (Rᵀ (p − p*), log(R*ᵀ R))`` [m, rad], both in the **frame's** axes
  (the rows of its body Jacobian): the position error rotated into the frame, and the rotation
  vector (axis × angle, angle in [0, π]) of the relative rotation ``R*ᵀ R`` that takes the
  anchor frame to the frame (:func:`rotation_log`; its axis has the same coordinates in both
  frames). ``p*`` is ``anchors[frame]``, ``R*`` is ``orientations[frame]`` (world axes); a
  missing one leaves its three rows without a position term. This is the error on SO(3) × R³,
  not the SE(3) logarithm (Pinocchio's ``log6``): the two agree to first order.

:class:`ContactDynamics` computes, from eomgen's own M and h (Newton–Euler,
:mod:`eomgen.numeric.newton_euler`) and the frame kinematics program:

* ``contact_jacobian(q)`` (m×n) and ``contact_bias(q, qd)`` (``J̇_c q̇``, (m,));
* ``constrained_forward_dynamics(q, qd, tau)`` → ``(q̈, F_c)`` from the KKT system
  ``[[M, −J_cᵀ], [J_c, 0]] [q̈; F_c] = [τ − h; −J̇_c q̇ − γ]``, or with ``damping=ε > 0`` the
  damped solution ``F_c = −(J_c M⁻¹ J_cᵀ + ε 1)⁻¹ (J̇_c q̇ + γ + J_c M⁻¹ (τ − h))`` (defined
  for redundant contacts);
* ``inverse_dynamics(q, qd, qdd, F_c)`` → ``τ = M q̈ + h − J_cᵀ F_c``;
* ``friction_cone(F_c)``: whether each contact's force lies in its Coulomb cone
  ``f_n ≥ 0, |f_t| ≤ μ f_n``, and by how much.

The generated modules have ``contact_jacobian``, ``contact_bias`` and (NumPy, CasADi, C)
``constrained_forward_dynamics`` with the same rows and signs, built from the scene contacts the
model carries (:mod:`eomgen.symbolic.frames`); docs/contact.md says what is and is not generated.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable, Mapping

import numpy as np

from ..dynamics import derive
from ..model import POINT, Contact, RobotModel
from ..symbolic.evaluate import compile_program
from ..symbolic.frames import derive_frames
from .newton_euler import M_crba, coriolis_times_qd, gravity_torques, numeric_model, rnea
from .so3 import so3_log

#: ``constrained_forward_dynamics`` without damping refuses a contact Jacobian whose smallest
#: singular value is below this fraction of its largest.
RANK_TOLERANCE = 1e-10


def derived_mass_and_bias(model: RobotModel) -> Callable:
    """``(q, qd) -> (M, h = C q̇ + g)`` from :func:`eomgen.derive`'s program, evaluated in
    Python floats (parameters at their default values); for :class:`ContactDynamics`."""
    dyn = derive(model, outputs=("M", "C", "g"))
    params = tuple(p.symbol for p in model.parameters)
    values = tuple(float(model.parameter_values[s]) for s in params)
    f = compile_program(dyn.program, dyn.q + dyn.qd + params)

    def mass_and_bias(q, qd):
        out = f(*map(float, q), *map(float, qd), *values)
        return out["M"], out["C"] @ np.asarray(qd, dtype=float) + out["g"].reshape(-1)

    return mass_and_bias


#: The logarithm of SO(3) (:func:`eomgen.numeric.so3.so3_log`) under the name the contact
#: error and its callers use.
rotation_log = so3_log


@dataclass(frozen=True)
class ContactDynamics:
    """Contact dynamics of ``model`` with ``contacts`` (see the module docstring).

    Attributes
    ----------
    model:
        The robot (a floating one from :func:`eomgen.model.floating.add_floating_base`, or not).
    contacts:
        The contacts, in the order of the rows of ``J_c`` and of ``F_c``.
    anchors:
        ``{frame: world position p*}`` [m] for the ``kp`` term of point and surface contacts.
    orientations:
        ``{frame: world rotation R*}`` (3×3) for the rotational ``kp`` term of surface
        contacts (module docstring).
    mass_and_bias:
        A function ``(q, qd) -> (M, h)`` with ``h = C q̇ + g``; None for eomgen's numeric
        Newton–Euler (:mod:`eomgen.numeric`: M by CRBA, h by two RNEA passes). :func:`derived_mass_and_bias`
        gives the derived program's, faster for repeated calls.
    frame_kinematics:
        A function ``(q, qd) -> {frame: {"p", "R", "J", "Jb", "dJqd", "dJbqd"}}``; None for the
        derived frame program (:func:`eomgen.symbolic.frames.derive_frames`).
        :func:`eomgen.numeric.frames.frame_function` gives the numeric recursion's, so that
        with ``mass_and_bias=None`` nothing comes from the derivation.
    """

    model: RobotModel
    contacts: tuple[Contact, ...]
    anchors: Mapping[str, np.ndarray] = field(default_factory=dict)
    orientations: Mapping[str, np.ndarray] = field(default_factory=dict)
    mass_and_bias: Callable | None = None
    frame_kinematics: Callable | None = None

    @cached_property
    def _numeric(self):
        return numeric_model(self.model)

    @cached_property
    def _frames(self):
        return derive_frames(self.model, sorted({c.frame for c in self.contacts}))

    @property
    def m(self) -> int:
        """Number of constraint rows."""
        return sum(c.size for c in self.contacts)

    def _kinematics(self, q, qd):
        if self.frame_kinematics is not None:
            return self.frame_kinematics(q, qd)
        return self._frames.evaluate(q, qd)

    def _rows(self, q, qd):
        """J_c (m, n), J̇_c q̇ (m,) and γ (m,) at one state."""
        kin = self._kinematics(q, qd)
        J, bias, gamma = [], [], []
        for c in self.contacts:
            f = kin[c.frame]
            if c.kind == POINT:
                Jc, b = f["J"][:3], f["dJqd"][:3]
                e = (f["p"] - np.asarray(self.anchors[c.frame]) if c.frame in self.anchors
                     and c.kp else np.zeros(3))
                g = c.kd * (Jc @ qd) + c.kp * e
            else:
                Jc, b = f["Jb"], f["dJbqd"]
                g = c.kd * (Jc @ qd)
                if c.kp:
                    g = g + c.kp * self.surface_error(c.frame, f)
            J.append(Jc)
            bias.append(b)
            gamma.append(g)
        n = self.model.dof
        if not J:
            return np.zeros((0, n)), np.zeros(0), np.zeros(0)
        return np.vstack(J), np.concatenate(bias), np.concatenate(gamma)

    def surface_error(self, frame: str, kinematics: Mapping | None = None, q=None
                      ) -> np.ndarray:
        """``(Rᵀ (p − p*), log(R*ᵀ R))`` (6,) [m, rad] of a surface contact on ``frame``, in the
        frame's axes (module docstring); zero rows where no anchor or orientation is given.
        ``kinematics``: the frame's entry of the frame program at the state, or give ``q``."""
        f = kinematics if kinematics is not None else \
            self._kinematics(np.asarray(q, float), np.zeros(self.model.dof))[frame]
        e = np.zeros(6)
        if frame in self.anchors:
            e[:3] = f["R"].T @ (f["p"] - np.asarray(self.anchors[frame], dtype=float))
        if frame in self.orientations:
            e[3:] = rotation_log(np.asarray(self.orientations[frame], dtype=float).T @ f["R"])
        return e

    def contact_jacobian(self, q) -> np.ndarray:
        """``J_c(q)``, (m, n): contact rows in ``contacts`` order, columns ``JOINT_NAMES``."""
        n = self.model.dof
        return self._rows(q, np.zeros(n))[0]

    def contact_bias(self, q, qd) -> np.ndarray:
        """``J̇_c q̇``, (m,): the constraint acceleration at ``q̈ = 0``."""
        return self._rows(q, np.asarray(qd, dtype=float))[1]

    def _mh(self, q, qd):
        if self.mass_and_bias is not None:
            return self.mass_and_bias(q, qd)
        nm = self._numeric
        return (M_crba(nm, q),
                coriolis_times_qd(nm, q, qd) + gravity_torques(nm, q))

    def constrained_forward_dynamics(self, q, qd, tau, damping: float = 0.0
                                     ) -> tuple[np.ndarray, np.ndarray]:
        """``(q̈, F_c)`` [(n,), (m,)] holding every contact (module docstring).

        ``damping = 0`` solves the KKT system exactly; ``damping > 0`` the damped system.

        Raises
        ------
        numpy.linalg.LinAlgError
            With ``damping = 0``, when ``J_c`` has dependent rows (redundant contacts, or a
            direction no joint can move the frame in, as out of a planar arm's plane): the
            forces are then not unique; use ``damping > 0``.
        """
        q, qd, tau = (np.asarray(x, dtype=float) for x in (q, qd, tau))
        M, h = self._mh(q, qd)
        J, bias, gamma = self._rows(q, qd)
        n, m = len(qd), len(bias)
        if damping <= 0 and m:
            sv = np.linalg.svd(J, compute_uv=False)
            if len(sv) < m or sv.min() <= RANK_TOLERANCE * sv.max():
                raise np.linalg.LinAlgError(
                    f"the contact Jacobian ({m}×{n}) has dependent rows (smallest singular "
                    f"value {sv.min():.3g}): the contact forces are not unique; use damping > 0")
        if damping > 0:
            Minv_J = np.linalg.solve(M, J.T)
            free = np.linalg.solve(M, tau - h)
            F = -np.linalg.solve(J @ Minv_J + damping * np.eye(m), bias + gamma + J @ free)
            return free + Minv_J @ F, F
        K = np.block([[M, -J.T], [J, np.zeros((m, m))]])
        x = np.linalg.solve(K, np.concatenate([tau - h, -bias - gamma]))
        return x[:n], x[n:]

    def inverse_dynamics(self, q, qd, qdd, F) -> np.ndarray:
        """``τ = M q̈ + C q̇ + g − J_cᵀ F_c``, (n,), for given contact forces ``F`` (m,)."""
        J = self.contact_jacobian(q)
        return rnea(self._numeric, q, qd, qdd) - J.T @ np.asarray(F, dtype=float)

    def friction_cone(self, F, q=None) -> list[tuple[bool, float]]:
        """For each contact with a ``mu``: ``(inside, margin)``, ``margin = μ f_n − |f_t|``
        [N] (negative outside; ``f_n < 0``, a pulling contact, is outside). Contacts without
        ``mu`` give ``(True, inf)``. Point contacts use their world ``normal``; surface
        contacts the frame's z axis (their force is in frame axes, so ``q`` is not needed)."""
        F = np.asarray(F, dtype=float)
        out, k = [], 0
        for c in self.contacts:
            f = F[k:k + 3]
            k += c.size
            if c.mu is None:
                out.append((True, float("inf")))
                continue
            normal = (np.asarray(c.normal, dtype=float) if c.kind == POINT
                      else np.array([0.0, 0.0, 1.0]))
            normal = normal / np.linalg.norm(normal)
            fn = float(f @ normal)
            ft = float(np.linalg.norm(f - fn * normal))
            margin = c.mu * fn - ft
            out.append((fn >= 0 and margin >= 0, margin))
        return out


__all__ = ["RANK_TOLERANCE", "ContactDynamics", "derived_mass_and_bias", "rotation_log"]
