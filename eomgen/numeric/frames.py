"""Frame kinematics by recursion, in NumPy: pose, Jacobians and J̇ q̇ of named links, the
independent counterpart of the derived frame program (:mod:`eomgen.symbolic.frames`).

For a link ``f`` (every link is a body of a :class:`~eomgen.numeric.NumericModel`, fixed-joint
links included), in the root frame of :mod:`eomgen.numeric.newton_euler` (the world), with the
same keys and conventions as :meth:`eomgen.symbolic.frames.FrameKinematics.evaluate`:

* ``p`` (3,) the frame origin [m], ``R`` (3, 3) its axes (``x_world = R x_f + p``);
* ``J`` (6, n), world-aligned at the frame origin (Pinocchio's ``LOCAL_WORLD_ALIGNED``):
  ``[ṗ; ω] = J q̇``, linear rows first;
* ``Jb`` (6, n), body (``LOCAL``): ``[Rᵀ ṗ; Rᵀ ω] = Jb q̇``;
* ``dJqd`` (6,): the classical acceleration ``[p̈; ω̇]`` at ``q̈ = 0``;
* ``dJbqd`` (6,): the body ``J̇ q̇``, ``[Rᵀ p̈ − ω_b × v_b; Rᵀ ω̇]`` at ``q̈ = 0`` (the spatial body
  acceleration, what Pinocchio's ``CONTACT_6D`` in ``LOCAL`` holds at zero).

The recursion runs outward in world axes. A revolute joint with world axis ``z`` turns its
child about an axis through the child's origin, a prismatic one slides it along ``z``::

    ω_i = ω_p + z q̇                               (revolute)
    v_i = v_p + ω_p × r  (+ z q̇, prismatic)         r = p_i − p_p
    ω̇_i = ω̇_p + ω_p × z q̇ + z q̈                   (revolute)
    a_i = a_p + ω̇_p × r + ω_p × (ω_p × r)  (+ 2 ω_p × z q̇ + z q̈, prismatic)

``v_i``, ``a_i`` being the velocity and classical acceleration of the body origin; a joint's
Jacobian column for a frame at ``p`` below it is ``(z × (p − p_j), z)`` (revolute) or ``(z, 0)``
(prismatic). Quaternion joints (NQ ≠ NV) run their chain at the chart's accelerations
``−n(v)`` (:mod:`eomgen.numeric.quaternion_chart`), which gives ``J̇ v = (J̇ v)_chart − J n(v)``;
coupled joints give ``J_tree T`` and the tree's bias at ``T q̇``.
"""

from __future__ import annotations

from typing import Callable, Iterable

import numpy as np

from .model import REVOLUTE, TURNING, NumericModel, numeric_model
from .newton_euler import world_state


def frame_kinematics(nm: NumericModel, q, qd=None, frames: Iterable[str] | None = None
                     ) -> dict[str, dict[str, np.ndarray]]:
    """``{frame: {"p", "R", "J", "Jb", "dJqd", "dJbqd"}}`` (module docstring) at one state.

    Parameters
    ----------
    nm : NumericModel
        A float64 model (:func:`~eomgen.numeric.numeric_model`).
    q : (nq,) array_like
        The configuration, as :func:`~eomgen.numeric.rnea` takes it.
    qd : (n,) array_like, optional
        Joint velocities (default zero).
    frames : iterable of str, optional
        Link names (default: every link).

    Raises
    ------
    KeyError
        For a name that is not a link of the model.
    """
    qd = np.zeros(nm.n) if qd is None else qd
    Rw, pw, z, w, v, wd, a, rate = world_state(nm, q, qd)
    body = {name: i for i, name in enumerate(nm.body_names)}
    out = {}
    for name in (nm.body_names if frames is None else frames):
        i = body[name]
        p, R = pw[i], Rw[i]
        J = np.zeros((6, nm.n_tree))
        k = i
        while k > 0:
            col = nm.q_index[k]
            if col >= 0:
                if nm.joint_type[k] in TURNING:
                    J[:3, col] = np.cross(z[k], p - pw[k])
                    J[3:, col] = z[k]
                if nm.joint_type[k] != REVOLUTE:  # prismatic, helical: lead · z
                    J[:3, col] = J[:3, col] + nm.lead[k] * z[k]
            k = nm.parent[k]
        if nm.coupling is not None:
            J = J @ nm.coupling
        Jb = np.vstack([R.T @ J[:3], R.T @ J[3:]])
        dJqd = np.concatenate([a[i], wd[i]])
        w_b, v_b = R.T @ w[i], R.T @ v[i]
        dJbqd = np.concatenate([R.T @ a[i] - np.cross(w_b, v_b), R.T @ wd[i]])
        out[name] = {"p": p, "R": R, "J": J, "Jb": Jb, "dJqd": dJqd, "dJbqd": dJbqd}
    return out


def frame_function(model, frames: Iterable[str] | None = None) -> Callable:
    """``(q, qd) -> frame_kinematics(nm, q, qd, frames)`` on ``model``'s numeric model (its
    parameters at their values), e.g. for
    :class:`eomgen.numeric.contacts.ContactDynamics`'s ``frame_kinematics``."""
    nm = numeric_model(model)
    frames = None if frames is None else tuple(frames)
    return lambda q, qd=None: frame_kinematics(nm, q, qd, frames)


__all__ = ["frame_function", "frame_kinematics"]
