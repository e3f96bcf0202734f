"""Identification (eomgen.identification, ``eomgen excite`` / ``eomgen identify``): β recovered
from efforts simulated by eomgen.numeric's Newton–Euler (an independent algorithm from the
regressor), within the reported standard deviations under noise, physically consistent fits
with PSD pseudo-inertias, and bad CSV files refused in one line with nothing written."""

from __future__ import annotations

import csv
import warnings
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest

import eomgen
from eomgen.errors import InvalidNumberError
from eomgen.identification import (IdentificationError, Measurements, MotionBounds,
                                   excitation_trajectory, measurements_csv, motion_bounds,
                                   observation_matrix, physical_fit, pseudo_inertia,
                                   read_measurements, simulate_measurements,
                                   weighted_least_squares)
from eomgen.parsers.urdf import JointLimit, joint_limits
from eomgen.regressor import base_parameters, derive_regressor

from support import ROOT, erd_robots_dir, run_in_process
from support.extras import need

need("scipy", reason="identification needs scipy")

PUMA = eomgen.example_path("puma560_dh")
PLANAR = eomgen.example_path("planar_2link")


@lru_cache(maxsize=None)
def setup(name: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = eomgen.load(eomgen.example_path(name))
    reg = derive_regressor(model)
    base = base_parameters(reg)
    ex = excitation_trajectory(reg, base, period=10.0, harmonics=3, seed=0, maxiter=10)
    return model, reg, base, ex


def simulated(name: str, samples: int, noise: float = 0.0, seed: int = 0):
    model, reg, base, ex = setup(name)
    t = np.arange(samples) * (10.0 / samples)
    data = simulate_measurements(model, ex.trajectory, t, noise=noise, seed=seed)
    W = observation_matrix(reg, base.base, data.q, data.qd, data.qdd)
    return data, W, base.beta(reg.numeric_parameters())


# ----------------------------------------------------------------------------------------------
# Estimation
# ----------------------------------------------------------------------------------------------


def test_excitation_lowers_the_condition_number_and_keeps_the_amplitude_bound():
    model, reg, base, ex = setup("puma560_dh")
    assert ex.condition < ex.initial_condition
    assert np.all(ex.trajectory.bound() <= 1.0 + 1e-12)
    q, qd, qdd = ex.trajectory.states(np.linspace(0, 10, 201))
    # periodic, and q̇, q̈ are the derivatives of q (central differences)
    np.testing.assert_allclose(q[0], q[-1], atol=1e-12)
    h = 1e-5
    qp, qdp, _ = ex.trajectory.states(np.array([1.3 + h]))
    qm, qdm, _ = ex.trajectory.states(np.array([1.3 - h]))
    _, qd1, qdd1 = ex.trajectory.states(np.array([1.3]))
    np.testing.assert_allclose((qp - qm) / (2 * h), qd1, atol=1e-8)
    np.testing.assert_allclose((qdp - qdm) / (2 * h), qdd1, atol=1e-7)
    again = excitation_trajectory(reg, base, period=10.0, harmonics=3, seed=0, maxiter=10)
    assert np.array_equal(again.trajectory.a, ex.trajectory.a)  # deterministic


def within(data, bounds, rtol=1e-12):
    """Whether sampled q, q̇, q̈ (N, n) respect ``bounds`` (checked on the samples alone)."""
    q, qd, qdd = data
    return (np.all(q >= bounds.lower) and np.all(q <= bounds.upper)
            and np.all(np.abs(qd) <= bounds.velocity) and np.all(np.abs(qdd) <= bounds.acceleration))


def test_excitation_respects_position_velocity_and_acceleration_bounds():
    """Limits that the unbounded optimum breaks: the bounded trajectory, sampled finely and
    checked on the samples, stays inside every one of them, and still excites β (rank 6)."""
    model, reg, base, free = setup("planar_2link")
    t = np.linspace(0, 10, 4001)
    limits = {"joint1": JointLimit(lower=0.2, upper=0.9, velocity=0.3),
              "joint2": JointLimit(lower=-0.5, upper=None)}
    bounds = motion_bounds(model.joint_names, 1.0, limits, max_velocity=0.5,
                           max_acceleration=0.15)
    np.testing.assert_array_equal(bounds.lower, [0.2, -0.5])
    np.testing.assert_array_equal(bounds.upper, [0.9, 1.0])
    np.testing.assert_array_equal(bounds.velocity, [0.3, 0.5])
    np.testing.assert_array_equal(bounds.acceleration, [0.15, 0.15])
    assert not within(free.trajectory.states(t), bounds)  # the bounds bite
    ex = excitation_trajectory(reg, base, period=10.0, harmonics=3, seed=0, maxiter=10,
                               bounds=bounds)
    states = ex.trajectory.states(t)
    assert within(states, bounds)
    # and not by standing still: each joint uses a fair part of its position range
    q = states[0]
    assert np.all(q.max(axis=0) - q.min(axis=0) > 0.1 * (bounds.upper - bounds.lower))
    W = observation_matrix(reg, base.base, *(x[::40] for x in states))
    assert np.linalg.matrix_rank(W) == len(base.base)


def test_motion_bounds_refuse_a_joint_with_no_room():
    names = ("joint1", "joint2")
    with pytest.raises(IdentificationError, match=r"arm.urdf: joint 'joint2': its limits "
                                                  r"\[1.5, 2\] and ±--amplitude 1 leave no room"):
        motion_bounds(names, 1.0, {"joint2": JointLimit(1.5, 2.0)}, source="arm.urdf")
    with pytest.raises(IdentificationError, match="joint 'joint1': velocity limit 0 leaves"):
        motion_bounds(names, 1.0, {"joint1": JointLimit(velocity=0.0)})
    with pytest.raises(IdentificationError, match="--max-acceleration must be positive"):
        motion_bounds(names, 1.0, max_acceleration=-1.0)


ARM_URDF = """<robot name="arm">
  <link name="base"/>
  <link name="link1"><inertial><mass value="1"/><origin xyz="0.5 0 0"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0.08" iyz="0" izz="0.08"/></inertial></link>
  <link name="link2"><inertial><mass value="1"/><origin xyz="0.5 0 0"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0.08" iyz="0" izz="0.08"/></inertial></link>
  <joint name="joint1" type="revolute"><parent link="base"/><child link="link1"/>
    <axis xyz="0 0 1"/><limit lower="{lower}" upper="1.2" velocity="0.4" effort="10"/></joint>
  <joint name="joint2" type="continuous"><parent link="link1"/><child link="link2"/>
    <origin xyz="1 0 0"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0" velocity="2" effort="10"/></joint>
</robot>
"""


def test_joint_limits_are_read_from_a_urdf(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(ARM_URDF.format(lower=0.3))
    assert joint_limits(path) == {"joint1": JointLimit(0.3, 1.2, 0.4, 10.0),
                                  "joint2": JointLimit(None, None, 2.0, 10.0)}  # continuous
    path.write_text(ARM_URDF.format(lower="low"))
    with pytest.raises(InvalidNumberError, match="joint 'joint1' <limit>.*lower 'low' is not a "
                                                 "number"):
        joint_limits(path)


def test_excite_keeps_the_urdf_limits_and_the_options(tmp_path):
    """eomgen excite on a URDF: the written samples (read back from the CSV, not from the
    optimiser) stay within joint1's <limit> [0.3, 1.2] rad and 0.4 rad/s, ±--amplitude 0.8 for
    the continuous joint2, --max-velocity 0.3 for joint2 and --max-acceleration 0.2."""
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(ARM_URDF.format(lower=0.3))
    data = tmp_path / "arm.csv"
    done = run_in_process("excite", urdf, "-o", data, "--samples", 400, "--amplitude", 0.8,
                       "--max-velocity", 0.3, "--max-acceleration", 0.2, "--quiet")
    assert done.returncode == 0, done.stderr
    read = read_measurements(data, ("joint1", "joint2"))
    bounds = MotionBounds(np.array([0.3, -0.8]), np.array([0.8, 0.8]), np.array([0.3, 0.3]),
                          np.array([0.2, 0.2]))  # written out, not from motion_bounds
    assert within((read.q, read.qd, read.qdd), bounds)
    assert read.q[:, 0].min() > 0.3 and read.q[:, 0].max() < 0.8
    # no room: joint1's limits [1.5, 2] lie outside ±--amplitude 1; nothing written
    urdf.write_text(ARM_URDF.format(lower=1.5).replace('upper="1.2"', 'upper="2"'))
    out = tmp_path / "none.csv"
    done = run_in_process("excite", urdf, "-o", out, "--quiet")
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith(f"eomgen: error: {urdf}: joint 'joint1': its limits [1.5, 2]")
    assert not out.exists()


def test_noise_free_puma_data_recover_the_base_parameters_to_1e_8():
    data, W, beta = simulated("puma560_dh", 200)
    est = weighted_least_squares(W, data.tau)
    error = np.abs(est.beta - beta)
    # relative per parameter where β is not zero; zero ones against the largest |β|
    scale = np.maximum(np.abs(beta), 1e-3 * np.abs(beta).max())
    assert np.max(error / scale) < 1e-8, np.max(error / scale)
    assert np.all(est.rms < 1e-9 * np.abs(data.tau).max())


def test_one_percent_noise_stays_within_three_reported_sigma():
    data, W, beta = simulated("puma560_dh", 300, noise=0.01, seed=0)
    est = weighted_least_squares(W, data.tau)
    z = np.abs(est.beta - beta) / est.std
    assert np.all(z < 3), z.max()
    # the per-joint σ_j estimate the noise actually added (1 % of each joint's RMS effort)
    clean = (W @ beta).reshape(data.tau.shape)
    added = np.sqrt(np.mean((data.tau - clean) ** 2, axis=0))
    np.testing.assert_allclose(est.sigma, added, rtol=0.2)


@pytest.mark.slow
def test_reported_standard_deviations_are_calibrated():
    """Over 40 noise draws the errors (β̂ − β) / std have unit spread, and 3 std covers
    what it should (99.7 % per parameter; all 36 at once for about 0.9973^36 = 91 % of draws,
    so a single draw may put one parameter outside 3 std)."""
    data, W, beta = simulated("puma560_dh", 300)
    rms = np.sqrt(np.mean(data.tau ** 2, axis=0))
    z = []
    for seed in range(40):
        noise = np.random.default_rng(seed).standard_normal(data.tau.shape) * 0.01 * rms
        est = weighted_least_squares(W, data.tau + noise)
        z.append((est.beta - beta) / est.std)
    z = np.array(z)
    assert 0.85 < z.std() < 1.15, z.std()
    assert np.mean(np.abs(z) < 3) > 0.985
    assert abs(np.mean(np.abs(z) < 1) - 0.683) < 0.05


def test_weights_matter_when_one_joint_is_much_noisier():
    """Gautier's weights: with joint 2 a hundred times noisier than joint 1, the weighted
    estimate is closer to the truth than ordinary least squares (planar arm, fixed seed)."""
    model, reg, base, ex = setup("planar_2link")
    data, W, beta = simulated("planar_2link", 400)
    rng = np.random.default_rng(7)
    tau = data.tau + rng.standard_normal(data.tau.shape) * np.array([0.001, 0.1])
    est = weighted_least_squares(W, tau)
    ols, *_ = np.linalg.lstsq(W, tau.reshape(-1), rcond=None)
    assert np.linalg.norm(est.beta - beta) < np.linalg.norm(ols - beta)
    assert np.all(np.abs(est.beta - beta) < 3 * est.std)


def test_positions_and_efforts_only_are_differentiated_through_a_filter(tmp_path):
    data, W, beta = simulated("planar_2link", 1000)
    path = tmp_path / "qt.csv"
    path.write_text(measurements_csv(data, derivatives=False))
    read = read_measurements(path, data.joint_names)
    assert read.differentiated and read.N < data.N
    keep = np.searchsorted(data.t, read.t)
    np.testing.assert_allclose(read.qd, data.qd[keep], atol=1e-3 * np.abs(data.qd).max())
    np.testing.assert_allclose(read.qdd, data.qdd[keep], atol=1e-2 * np.abs(data.qdd).max())
    model, reg, base, _ = setup("planar_2link")
    Wf = observation_matrix(reg, base.base, read.q, read.qd, read.qdd)
    est = weighted_least_squares(Wf, read.tau)
    assert np.max(np.abs(est.beta - beta)) < 1e-2 * np.abs(beta).max()


def test_cutoff_filters_given_velocities_and_efforts_alike(tmp_path):
    """With qd_, qdd_ columns, a cut-off filters q, q̇, q̈ and τ (it used to be ignored, the
    file read as is): 5 % white noise on q̈ and τ is cut to well below half, the motion
    (0.1–0.3 Hz) passes; the ends are trimmed and the rest decimated; no t, no filtering."""
    data, _, beta = simulated("planar_2link", 1000)  # 100 Hz over 10 s
    rng = np.random.default_rng(5)
    noise = {name: 0.05 * np.sqrt(np.mean(getattr(data, name) ** 2, axis=0))
             * rng.standard_normal(data.tau.shape) for name in ("qdd", "tau")}
    noisy = Measurements(data.joint_names, data.t, data.q, data.qd, data.qdd + noise["qdd"],
                         data.tau + noise["tau"])
    path = tmp_path / "noisy.csv"
    path.write_text(measurements_csv(noisy))
    raw = read_measurements(path, data.joint_names)
    assert raw.cutoff is None and np.array_equal(raw.tau, noisy.tau)  # no cut-off: as read
    read = read_measurements(path, data.joint_names, cutoff=2.0)
    assert read.cutoff == 2.0 and not read.differentiated
    keep = np.arange(150, 850, 25)  # 3 periods of 2 Hz trimmed each end, every fs/(2 fc)
    np.testing.assert_array_equal(read.t, data.t[keep])
    for name in ("q", "qd"):  # noise-free signals pass the filter unchanged
        clean = getattr(data, name)[keep]
        np.testing.assert_allclose(getattr(read, name), clean, atol=1e-3 * np.abs(clean).max())
    for name in ("qdd", "tau"):
        clean = getattr(data, name)[keep]
        before = np.sqrt(np.mean((getattr(noisy, name)[keep] - clean) ** 2))
        after = np.sqrt(np.mean((getattr(read, name) - clean) ** 2))
        assert after < 0.4 * before, (name, after / before)
    model, reg, base, _ = setup("planar_2link")
    W = observation_matrix(reg, base.base, read.q, read.qd, read.qdd)
    est = weighted_least_squares(W, read.tau)
    assert np.all(np.abs(est.beta - beta) < 3 * est.std), (est.beta - beta) / est.std
    no_t = tmp_path / "no_t.csv"
    no_t.write_text("\n".join(drop_column(path.read_text().splitlines(), "t")) + "\n")
    with pytest.raises(IdentificationError, match="missing column 't' .needed to filter at "
                                                  "the cut-off 2 Hz"):
        read_measurements(no_t, data.joint_names, cutoff=2.0)


def test_identify_cutoff_on_full_data_is_reported(tmp_path):
    data, _, _ = simulated("planar_2link", 400)
    path = tmp_path / "planar.csv"
    path.write_text(measurements_csv(data))
    out = tmp_path / "id"
    done = run_in_process("identify", PLANAR, path, "-o", out, "--quiet", "--cutoff", 4)
    assert done.returncode == 0, done.stderr
    assert "q, q̇, q̈, τ zero-phase low-pass filtered at 4 Hz" in done.stdout
    # 40 Hz sampling: 3 periods of 4 Hz (30 samples) trimmed each end, every 5th kept
    assert f"{len(range(30, 370, 5))} samples × 2 joints" in done.stdout


def test_csv_round_trip_is_exact(tmp_path):
    data, _, _ = simulated("planar_2link", 20, noise=0.01)
    path = tmp_path / "d.csv"
    path.write_text(measurements_csv(data))
    read = read_measurements(path, data.joint_names)
    for name in ("t", "q", "qd", "qdd", "tau"):
        assert np.array_equal(getattr(read, name), getattr(data, name))


def test_pseudo_inertia_is_psd_exactly_for_physical_bodies():
    rng = np.random.default_rng(0)
    m, c = 2.0, rng.uniform(-0.1, 0.1, 3)
    S = np.diag([0.01, 0.02, 0.005])  # second moments about the COM: a real body
    Ic = np.trace(S) * np.eye(3) - S
    I = Ic + m * (c @ c * np.eye(3) - np.outer(c, c))
    pi = [m, *(m * c), I[0, 0], I[0, 1], I[1, 1], I[0, 2], I[1, 2], I[2, 2]]
    J = pseudo_inertia(pi)
    np.testing.assert_allclose(J[:3, :3], S + m * np.outer(c, c), atol=1e-15)  # ∫ r rᵀ dm
    assert np.linalg.eigvalsh(J)[0] > 0
    # a thin rod about its COM only along z breaks the triangle inequality: J is not PSD
    assert np.linalg.eigvalsh(pseudo_inertia([1, 0, 0, 0, 0, 0, 0, 0, 0, 1.0]))[0] < 0


def test_physical_fit_returns_psd_pseudo_inertias():
    need("cvxpy", reason="the physically consistent fit is an SDP")
    model, reg, base, _ = setup("puma560_dh")
    data, W, beta = simulated("puma560_dh", 200, noise=0.01, seed=1)
    est = weighted_least_squares(W, data.tau)
    fit = physical_fit(reg, base, W, data.tau, est.sigma)
    eig = [np.linalg.eigvalsh(pseudo_inertia(fit.pi[10 * k:10 * k + 10]))[0]
           for k in range(reg.n)]
    scale = [np.abs(fit.pi[10 * k:10 * k + 10]).max() for k in range(reg.n)]
    assert all(e >= -1e-7 * s for e, s in zip(eig, scale)), eig
    np.testing.assert_allclose(fit.min_eigenvalues, eig)
    # the description's links 1 and 3 are not physical, yet the unidentifiable parts leave room
    # for a consistent π fitting as well as the unconstrained estimate
    assert np.all(fit.rms < 1.05 * est.rms + 1e-12)
    np.testing.assert_allclose(fit.beta, base.beta(fit.pi))
    # noise-free (weights from rounding errors, up to ~1e15): still a fit to 3e-5 of each
    # joint's RMS effort
    clean, W, _ = simulated("puma560_dh", 200)
    exact = physical_fit(reg, base, W, clean.tau,
                         weighted_least_squares(W, clean.tau).sigma)
    assert np.all(exact.rms < 1e-4 * np.sqrt(np.mean(clean.tau ** 2, axis=0)))
    assert np.all(exact.min_eigenvalues > -1e-7)


def test_physical_fit_of_a_physical_robot_keeps_the_estimate():
    """τ = W β(π) for a random π whose pseudo-inertias are positive definite, 1 % noise: the
    constrained fit lands within 3 std of the truth, as the unconstrained one does."""
    need("cvxpy", reason="the physically consistent fit is an SDP")
    model, reg, base, _ = setup("puma560_dh")
    _, W, _ = simulated("puma560_dh", 200)
    rng = np.random.default_rng(3)
    pi = []
    for _ in range(reg.n):
        m, c = rng.uniform(1, 5), rng.uniform(-0.1, 0.1, 3)
        A = rng.standard_normal((3, 3))
        S = 0.01 * A @ A.T + 1e-3 * np.eye(3)  # second moments about the COM
        I = np.trace(S) * np.eye(3) - S + m * (c @ c * np.eye(3) - np.outer(c, c))
        pi += [m, *(m * c), I[0, 0], I[0, 1], I[1, 1], I[0, 2], I[1, 2], I[2, 2]]
    beta = base.beta(np.array(pi))
    tau = (W @ beta).reshape(-1, reg.n)
    tau = tau + rng.standard_normal(tau.shape) * 0.01 * np.sqrt(np.mean(tau ** 2, axis=0))
    est = weighted_least_squares(W, tau)
    fit = physical_fit(reg, base, W, tau, est.sigma)
    assert np.all(np.abs(fit.beta - beta) < 3 * est.std)
    assert np.all(fit.min_eigenvalues > -1e-7)


# ----------------------------------------------------------------------------------------------
# Command line
# ----------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_excite_then_identify_puma(tmp_path):
    need("cvxpy", reason="--physical needs cvxpy")
    data = tmp_path / "puma.csv"
    result = run_in_process("excite", PUMA, "-o", data, "--samples", 150, "--noise", 0.01,
                         "--quiet")
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[-1] == str(data)
    out = tmp_path / "id"
    result = run_in_process("identify", PUMA, data, "-o", out, "--quiet", "--physical")
    assert result.returncode == 0, result.stderr
    assert "min eig of its body's pseudo-inertia J" in result.stdout
    names = sorted(p.name for p in out.iterdir())
    assert names == ["identify_puma560.csv", "identify_puma560.md", "identify_puma560.png"]
    rows = (out / "identify_puma560.csv").read_text().splitlines()
    assert len(rows) == 1 + 36 and rows[0].startswith("name,expression,estimate,std")
    png = (out / "identify_puma560.png").read_bytes()
    again = tmp_path / "id2"
    assert run_in_process("identify", PUMA, data, "-o", again, "--quiet",
                       "--physical").returncode == 0
    assert (again / "identify_puma560.png").read_bytes() == png  # deterministic
    assert "| 36 | ZZ6 | `ZZ6` |" in result.stdout


def planar_csv(tmp_path: Path, samples: int = 30) -> Path:
    data, _, _ = simulated("planar_2link", samples)
    path = tmp_path / "planar.csv"
    path.write_text(measurements_csv(data))
    return path


def edited(tmp_path: Path, edit) -> Path:
    lines = planar_csv(tmp_path).read_text().splitlines()
    path = tmp_path / "bad.csv"
    path.write_text("\n".join(edit(lines)) + "\n")
    return path


def drop_column(lines, name):
    k = lines[0].split(",").index(name)
    return [",".join(f for i, f in enumerate(line.split(",")) if i != k) for line in lines]


BAD = {
    "missing": (lambda lines: drop_column(lines, "qdd_joint2"),
                "line 1: missing column 'qdd_joint2'"),
    "extra": (lambda lines: [lines[0] + ",tau_joint3"] + [line + ",0" for line in lines[1:]],
              "line 1: unknown column 'tau_joint3'"),
    "nan": (lambda lines: lines[:6] + [lines[6].rsplit(",", 1)[0] + ",nan"] + lines[7:],
            "line 7, column tau_joint2: 'nan' is not a finite number"),
    "few": (lambda lines: lines[:3], "2 samples give 4 equations for 6 base parameters"),
    "no_t": (lambda lines: drop_column(drop_column(drop_column(drop_column(drop_column(
        lines, "t"), "qd_joint1"), "qd_joint2"), "qdd_joint1"), "qdd_joint2"),
        "line 1: missing column 't' (needed to differentiate q"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_csv_is_one_line_exit_2_and_nothing_written(tmp_path, case):
    edit, message = BAD[case]
    path = edited(tmp_path, edit)
    out = tmp_path / "out"
    result = run_in_process("identify", PLANAR, path, "-o", out, "--quiet")
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and result.stderr.startswith("eomgen: error: ")
    assert str(path) in result.stderr and message in result.stderr, result.stderr
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.csv", "planar.csv"]


def test_unexciting_data_name_the_rank(tmp_path):
    data = Measurements(("joint1", "joint2"), np.arange(10.0), np.zeros((10, 2)),
                        np.zeros((10, 2)), np.zeros((10, 2)), np.ones((10, 2)))
    path = tmp_path / "still.csv"
    path.write_text(measurements_csv(data))
    model, reg, base, _ = setup("planar_2link")
    read = read_measurements(path, model.joint_names)
    W = observation_matrix(reg, base.base, read.q, read.qd, read.qdd)
    with pytest.raises(IdentificationError, match=r"still.csv: the 10 samples excite only \d "
                                                  r"of the 6 base parameters"):
        weighted_least_squares(W, read.tau, str(path))


def test_excite_refuses_a_folder_as_output_before_any_work(tmp_path):
    result = run_in_process("excite", PLANAR, "-o", tmp_path)
    assert result.returncode == 2 and "it is a folder, not a file" in result.stderr
    assert result.stderr.count("\n") == 1


def test_excite_reports_the_optimisation_as_it_goes(tmp_path):
    """Issue 29: excite optimised 13-40 s without a word; each iteration of the optimiser is a
    stage line (with the time, in a log) giving the best condition number so far, and --quiet
    silences them."""
    import re

    from eomgen.identification.excitation import EXCITATION_ITERATIONS

    done = run_in_process("excite", "scara_rrp", "-o", tmp_path / "a.csv", "--samples", 50)
    assert done.returncode == 0, done.stderr
    line = re.compile(r"^eomgen: optimising: (\d+)/(\d+), cond ([0-9.e+]+), (\d+) evaluations "
                      r"\[\+\d+\.\d s\]$")
    steps = [line.match(text) for text in done.stderr.splitlines()]
    steps = [(int(m[1]), int(m[2]), float(m[3]), int(m[4])) for m in steps if m]
    assert len(steps) >= 2 and [s[0] for s in steps] == list(range(1, len(steps) + 1))
    assert all(s[1] == EXCITATION_ITERATIONS for s in steps)
    conds, evaluations = [s[2] for s in steps], [s[3] for s in steps]
    assert conds == sorted(conds, reverse=True) and evaluations == sorted(set(evaluations))
    said = re.search(r"cond\(Y_base\) ([0-9.e+]+) at the random start, ([0-9.e+]+) optimised",
                     done.stdout)
    assert float(said[2]) <= conds[-1] * (1 + 1e-3) < float(said[1])
    quiet = run_in_process("excite", "scara_rrp", "-o", tmp_path / "b.csv", "--samples", 50,
                           "--quiet")
    assert quiet.returncode == 0 and quiet.stderr == ""
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()


def test_excite_and_identify_a_scene_of_the_panda(tmp_path):
    """--scene: the Panda reduced to its shoulder and elbow; columns named after the joints
    the scene keeps (and the viscous friction its URDF declares, simulated and fitted), the
    description's β recovered within 3 std from 1 % noise."""
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    urdf = robots / "panda_description/urdf/panda.urdf"
    scene = ROOT / "examples/scenes/panda_two_joints.yaml"
    data = tmp_path / "panda.csv"
    done = run_in_process("excite", urdf, "--scene", scene, "-o", data, "--samples", 100,
                       "--noise", 0.01, "--quiet")
    assert done.returncode == 0, done.stderr
    assert data.read_text().splitlines()[0] == (
        "t,q_panda_joint2,q_panda_joint4,qd_panda_joint2,qd_panda_joint4,qdd_panda_joint2,"
        "qdd_panda_joint4,tau_panda_joint2,tau_panda_joint4")
    out = tmp_path / "id"
    done = run_in_process("identify", urdf, data, "--scene", scene, "-o", out, "--quiet")
    assert done.returncode == 0, done.stderr
    rows = list(csv.DictReader((out / "identify_panda.csv").open()))
    assert [r["name"] for r in rows] == ["MX1R", "MY1R", "ZZ1R", "MX2", "MY2", "ZZ2", "FV1",
                                         "FV2"]
    for r in rows:
        assert abs(float(r["estimate"]) - float(r["description"])) < 3 * float(r["std"]), r
