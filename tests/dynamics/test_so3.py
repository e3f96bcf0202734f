"""The one SO(3) floor (:mod:`eomgen.numeric.so3`): the skew matrix, the exponential and the
logarithm against independent references: NumPy's cross product, SciPy's rotation vectors
(``scipy.spatial.transform.Rotation``) and mpmath's matrix exponential; and the names the rest
of the package imports them by are these functions, not copies.
"""

from __future__ import annotations

import numpy as np
import pytest

from support.extras import need
from eomgen.numeric import contacts
from eomgen.model import configuration as quaternion_joints
from eomgen.numeric import contacts as numeric_contacts
from eomgen.numeric.so3 import left_jacobian, rotation_about, skew, so3_exp, so3_log

need("scipy", reason="SciPy's rotation vectors are the reference")
from scipy.spatial.transform import Rotation  # noqa: E402

EPS = np.finfo(float).eps
RNG = np.random.default_rng(20240611)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


AXES = [_unit(RNG.normal(size=3)) for _ in range(4)] + [np.eye(3)[k] for k in range(3)]
#: Angles [rad] below π: near 0, ordinary, around π/2 (where the logarithm changes method),
#: near π.
ANGLES = [1e-12, 1e-9, 1e-7, 1e-5, 0.3, 1.0, np.pi / 2 - 1e-9, np.pi / 2 + 1e-9, 2.5,
          np.pi - 1e-3, np.pi - 1e-6, np.pi - 1e-9]


def test_skew_times_x_is_the_cross_product():
    for _ in range(20):
        w, x = RNG.normal(size=3), RNG.normal(size=3)
        bound = 4 * EPS * np.linalg.norm(w) * np.linalg.norm(x)
        np.testing.assert_allclose(skew(w) @ x, np.cross(w, x), rtol=0, atol=bound)
        np.testing.assert_array_equal(skew(w), -skew(w).T)


def test_skew_and_rodrigues_in_mpmath():
    """With the mpmath numbers the entries are mpmath's, and the rotation about an axis is
    mpmath's own matrix exponential of ``θ [k]×`` to 40 digits."""
    mpmath = need("mpmath")
    from eomgen.analysis.precision import MPMATH

    with mpmath.workdps(50):
        v = [mpmath.mpf(1), mpmath.mpf(-2), mpmath.mpf("0.5")]
        axis = [x / mpmath.norm(v) for x in v]
        theta = mpmath.mpf("2.9")
        K = skew(axis, MPMATH)
        assert K.dtype == object and all(isinstance(v, mpmath.mpf) for v in K.flat)
        x = [mpmath.mpf(3), mpmath.mpf(-1), mpmath.mpf(2)]
        cross = [axis[1] * x[2] - axis[2] * x[1], axis[2] * x[0] - axis[0] * x[2],
                 axis[0] * x[1] - axis[1] * x[0]]
        assert all(abs(a - b) < mpmath.mpf(10) ** -45 for a, b in zip(K @ np.array(x), cross))
        R = rotation_about(axis, theta, MPMATH)
        expected = mpmath.expm(mpmath.matrix(K.tolist()) * theta)
        assert max(abs(R[r, c] - expected[r, c]) for r in range(3) for c in range(3)) \
            < mpmath.mpf(10) ** -40


def test_exp_is_scipys_rotation():
    for axis in AXES:
        for theta in ANGLES + [np.pi, 4.0]:
            w = theta * axis
            np.testing.assert_allclose(so3_exp(w), Rotation.from_rotvec(w).as_matrix(),
                                       rtol=0, atol=8 * EPS)
    np.testing.assert_array_equal(so3_exp(np.zeros(3)), np.eye(3))


def test_log_of_exp_is_the_vector_below_pi():
    """``log(exp(w)) = w`` for ``|w| < π``, and SciPy's rotation vector of the same matrix."""
    for axis in AXES:
        for theta in ANGLES:
            w = theta * axis
            R = Rotation.from_rotvec(w).as_matrix()
            got = so3_log(R)
            np.testing.assert_allclose(got, w, rtol=0, atol=16 * EPS, err_msg=f"{w}")
            np.testing.assert_allclose(got, Rotation.from_matrix(R).as_rotvec(),
                                       rtol=0, atol=16 * EPS, err_msg=f"{w}")


@pytest.mark.parametrize("theta", [0.0, 1e-12, 1e-8, 1e-6, np.pi - 1e-6, np.pi - 1e-10, np.pi])
def test_exp_of_log_is_the_rotation_near_zero_and_pi(theta):
    """``exp(log R) = R`` near 0, near π and at π exactly (where ``u`` and ``−u`` are both
    logarithms: the angle is π and the rotation the same)."""
    for axis in AXES:
        R = Rotation.from_rotvec(theta * axis).as_matrix()
        w = so3_log(R)
        assert np.linalg.norm(w) <= np.pi * (1 + 4 * EPS)
        np.testing.assert_allclose(np.linalg.norm(w), theta, rtol=0, atol=8 * EPS)
        np.testing.assert_allclose(so3_exp(w), R, rtol=0, atol=16 * EPS)
        if theta < np.pi:  # below π the logarithm is unique: SciPy's
            np.testing.assert_allclose(w, Rotation.from_matrix(R).as_rotvec(), rtol=0,
                                       atol=16 * EPS)


def test_log_at_pi_of_exact_half_turns():
    """Half turns written exactly (``2 u uᵀ − 1``, and the diagonal ones)."""
    for R in [np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, 1.0, -1.0]), np.diag([-1.0, -1.0, 1.0])]:
        w = so3_log(R)
        np.testing.assert_allclose(np.linalg.norm(w), np.pi, rtol=0, atol=4 * EPS)
        np.testing.assert_array_equal(so3_exp(w).round(15), R)
    for axis in AXES:
        R = 2 * np.outer(axis, axis) - np.eye(3)
        w = so3_log(R)
        np.testing.assert_allclose(abs(w @ axis), np.pi, rtol=0, atol=8 * EPS)
        np.testing.assert_allclose(so3_exp(w), R, rtol=0, atol=16 * EPS)


def test_left_jacobian_is_the_se3_exponentials_translation():
    """``V(w) ν`` is the translation of ``exp([ν, w])``: the integral ``∫₀¹ exp(s[w]×) ν ds``
    (Simpson's rule on 2001 points), also below its series threshold."""
    s = np.linspace(0.0, 1.0, 2001)
    weights = np.ones_like(s)
    weights[1:-1:2], weights[2:-1:2] = 4, 2
    weights *= (s[1] - s[0]) / 3
    for w in [RNG.normal(size=3), 1e-7 * RNG.normal(size=3), 3.0 * AXES[0]]:
        nu = RNG.normal(size=3)
        integral = sum(c * (so3_exp(t * w) @ nu) for c, t in zip(weights, s))
        np.testing.assert_allclose(left_jacobian(w) @ nu, integral, rtol=0, atol=1e-12)


def test_the_package_has_one_so3():
    """The names other modules and the docs use are the floor's functions themselves."""
    assert contacts.rotation_log is numeric_contacts.rotation_log is so3_log
    assert quaternion_joints.so3_log is so3_log and quaternion_joints.so3_exp is so3_exp
    assert quaternion_joints.skew is skew and quaternion_joints.left_jacobian is left_jacobian
