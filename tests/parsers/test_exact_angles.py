"""Exact rotation angles: ``rpy: [0, 0, pi/6]`` in eomgen's YAML stays √3/2 and 1/2 into M, C, g,
and a URDF float within 1e-12 of a multiple of π/12 (``0.5235987755982988``) snaps to it,
reported as the entries' snapping is; ``--no-snap`` keeps the floats.

The arm is the textbook planar two-link arm whose second joint is turned by π/6 about z, so
that M₁₁ = m₁ l_c1² + m₂ (l₁² + l_c2² + 2 l₁ l_c2 cos(q₂ + π/6)) + I₁ + I₂ (the textbook's
formula with the angle between the links shifted by π/6): the closed form, the same M from the
URDF, and Pinocchio's CRBA on the URDF (its own parser, floats) are the references.
"""

from __future__ import annotations

import importlib.util

import math

import numpy as np
import pytest
import sympy as sp

import eomgen
from eomgen.dynamics import derive
from eomgen.model import ANGLE_SNAP_TOLERANCE, snap_summary
from eomgen.symbolic.identities import check_zero
from support import load_module, run_in_process, write
from support.robots import turned_arm_urdf, turned_arm_yaml
from support.extras import need

PI_6 = 0.5235987755982988  # the double nearest π/6

@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("turned")
    return {"yaml": write(folder / "turned_2r.yaml", turned_arm_yaml("pi/6")),
            "urdf": write(folder / "turned_2r.urdf", turned_arm_urdf(repr(PI_6))),
            "folder": folder}


@pytest.fixture(scope="module")
def exact(files):
    return derive(eomgen.load(files["yaml"]), outputs=("M", "C", "g"))


@pytest.fixture(scope="module")
def snapped(files):
    return derive(eomgen.load(files["urdf"]), outputs=("M", "C", "g"))


def values(dyn) -> dict:
    return {p.symbol: sp.Integer(int(p.value)) if float(p.value).is_integer()
            else sp.Rational(str(p.value)) for p in dyn.model.parameters}


def test_pi_over_6_in_yaml_is_an_exact_rotation(files):
    model = eomgen.load(files["yaml"])
    rotation = next(j for j in model.joints if j.name == "joint2").origin.rotation
    assert rotation[0][0] == sp.sqrt(3) / 2 and rotation[1][0] == sp.Rational(1, 2)
    assert rotation[0][1] == -sp.Rational(1, 2) and rotation[2][2] == 1
    assert "snapped" not in dict(model.info)  # exact as written: nothing snapped


def test_the_derived_M_C_g_are_exact_and_M_is_the_closed_form(exact):
    for matrix in (exact.M, exact.C, exact.g):
        assert not matrix.atoms(sp.Float) and matrix.has(sp.sqrt(3))
    s = {p.name: p.symbol for p in exact.model.parameters}
    q2 = exact.q[1]
    closed = (s["m1"] * s["lc1"]**2 + s["I1"] + s["I2"]
              + s["m2"] * (s["l1"]**2 + s["lc2"]**2 + 2 * s["l1"] * s["lc2"] * sp.cos(q2 + sp.pi / 6)))
    assert sp.expand(sp.expand_trig(exact.M[0, 0] - closed)) == 0
    off = s["m2"] * (s["lc2"]**2 + s["l1"] * s["lc2"] * sp.cos(q2 + sp.pi / 6)) + s["I2"]
    assert sp.expand(sp.expand_trig(exact.M[0, 1] - off)) == 0
    # and Mdot - 2C is skew-symmetric exactly, the check that used to meet 4e-15
    N = sum((exact.M.diff(q) * qd for q, qd in zip(exact.q, exact.qd)), sp.zeros(2, 2)) \
        - 2 * exact.C
    skew = check_zero("skew", (N + N.T).applyfunc(sp.simplify), N)
    assert skew.exact and skew.holds and str(skew) == "skew exactly"


def test_a_urdf_angle_near_pi_over_6_snaps_and_says_so(files, exact, snapped):
    snaps = dict(snapped.model.info)["snapped"]
    assert len(snaps) == 1 and snaps[0].is_angle and snaps[0].target == sp.pi / 6
    assert snaps[0].what == f"angle {PI_6!r}"
    assert snaps[0].change == pytest.approx(abs(float(sp.N(sp.pi / 6 - sp.Float(PI_6, 30), 30))))
    assert 0 < snaps[0].change < 1e-16
    summary = snap_summary(snaps)
    assert summary.startswith("snapped 1 angle within 1e-12 of a multiple of π/12 to exact")
    assert "--no-snap" in summary
    # the same exact M as the YAML's at its values
    assert not snapped.M.atoms(sp.Float)
    assert (snapped.M - exact.M.xreplace(values(exact))).applyfunc(sp.expand) == sp.zeros(2, 2)


def test_no_snap_keeps_the_floats(files, snapped):
    kept = derive(eomgen.load(files["urdf"], snap=False), outputs=("M",))
    assert kept.M.atoms(sp.Float) and not kept.M.has(sp.sqrt(3))
    assert "snapped" not in dict(kept.model.info)
    rotation = next(j for j in kept.model.joints if j.name == "joint2").origin.rotation
    assert float(rotation[0][0]) == math.cos(PI_6) and float(rotation[1][0]) == math.sin(PI_6)
    at = {snapped.q[1]: sp.Rational(7, 10)}
    difference = (kept.M.xreplace(at) - snapped.M.xreplace(at)).evalf(30)
    assert max(abs(float(e)) for e in difference) < 1e-14


@pytest.mark.parametrize("angle, snaps", [
    (repr(PI_6 + 2e-12), False),        # beyond 1e-12: kept as floats
    ("2.356194490192345", True),        # 3π/4
    ("-0.2617993877991494", True),      # -π/12
    ("1.5707963267948966", False),      # π/2: the entries' snapping, as before
])
def test_which_angles_snap(tmp_path, angle, snaps):
    model = eomgen.load(write(tmp_path / "r.urdf", turned_arm_urdf(angle)))
    rotation = next(j for j in model.joints if j.name == "joint2").origin.rotation
    recorded = dict(model.info).get("snapped", ())
    assert any(s.is_angle for s in recorded) is snaps
    assert all(s.change <= ANGLE_SNAP_TOLERANCE for s in recorded if s.is_angle)
    entries = [e for row in rotation for e in row]
    assert (not any(isinstance(e, sp.Float) for e in entries)) is (snaps or angle.startswith("1.57"))
    R = np.array([[float(e) for e in row] for row in rotation])
    c, s = math.cos(float(angle)), math.sin(float(angle))
    assert np.abs(R - [[c, -s, 0], [s, c, 0], [0, 0, 1]]).max() < 1e-11


def test_an_angle_without_a_radical_cosine_is_read_as_floats(tmp_path):
    """cos(π/7) has no square-root form in SymPy: the angle is read as floats, as before."""
    model = eomgen.load(write(tmp_path / "r.yaml", turned_arm_yaml("pi/7")))
    rotation = next(j for j in model.joints if j.name == "joint2").origin.rotation
    assert isinstance(rotation[0][0], sp.Float) and float(rotation[0][0]) == math.cos(math.pi / 7)


def test_snapped_M_equals_pinocchios_crba(files, snapped):
    """Pinocchio reads the URDF itself (floats, its own parser): the snapped exact M agrees."""
    pin = need("pinocchio", reason="Pinocchio is the independent reference")
    model = pin.buildModelFromUrdf(str(files["urdf"]))
    data = model.createData()
    M_of = sp.lambdify(snapped.q, snapped.M, "numpy")
    for q in np.random.default_rng(3).uniform(-3, 3, (5, 2)):
        M_pin = pin.crba(model, data, q)
        M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
        assert np.abs(np.array(M_of(*q), dtype=float) - M_pin).max() < 1e-13


def test_generated_modules_with_sqrt3_agree_with_pinocchio(files):
    """`eomgen generate` prints √3 as a literal: the NumPy and PyTorch modules (torch.sqrt
    takes no number) give Pinocchio's M on the URDF."""
    pin = need("pinocchio", reason="Pinocchio is the independent reference")
    torch_available = importlib.util.find_spec("torch") is not None
    backends = "numpy,torch" if torch_available else "numpy"
    out = files["folder"] / "generated"
    result = run_in_process("generate", files["yaml"], "--backend", backends, "--no-cache",
                            "--quiet", "-o", out)
    assert result.returncode == 0, result.stderr
    assert "sqrt" not in (out / "turned_2r_numpy.py").read_text()
    model = pin.buildModelFromUrdf(str(files["urdf"]))
    data = model.createData()
    numpy_module = load_module(out / "turned_2r_numpy.py", "turned_2r_numpy_angles")
    q = np.array([0.4, -1.3])
    M_pin = pin.crba(model, data, q)
    M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
    assert np.abs(numpy_module.mass_matrix(q) - M_pin).max() < 1e-13
    if torch_available:
        import torch

        torch_module = load_module(out / "turned_2r_torch.py", "turned_2r_torch_angles")
        M_torch = torch_module.mass_matrix(torch.tensor(q, dtype=torch.float64)).numpy()
        assert np.abs(M_torch - M_pin).max() < 1e-13


def test_among_floats_the_snapped_angle_costs_no_operation(tmp_path):
    """With a float mass the model is derived in floats (``float_constants``): the snapped
    π/6 folds into the floats, and the program is as long as the one of the floats kept."""
    from eomgen.symbolic.opcount import program_operation_count

    path = write(tmp_path / "r.urdf", turned_arm_urdf(repr(PI_6)).replace(
        '<mass value="2"/>', '<mass value="2.5"/>'))
    snapped, kept = (derive(eomgen.load(path, snap=snap), outputs=("M", "g"), simplify=False)
                     for snap in (True, False))
    assert dict(snapped.model.info)["snapped"] and not snapped.M.has(sp.sqrt(3))
    assert program_operation_count(snapped.program) == program_operation_count(kept.program)
