"""The generated regressor functions (issue 15: ``regressor``, ``inertial_parameters``,
``base_regressor``, ``base_parameters``, the energy regressors) in every backend, against
independent computations: eomgen.numeric's Newton–Euler and energies (plus the actuator terms
written out by hand), the generated module's own ``inverse_dynamics``, and Pinocchio's
``computeJointTorqueRegressor`` column by column on the UR5."""

from __future__ import annotations

import importlib.util
import warnings

import numpy as np
import pytest

import eomgen
from support import ROOT, erd_robots_dir, random_states
from eomgen.codegen.generate import render_files
from eomgen.errors import UnsupportedFeatureWarning
from eomgen.numeric import kinetic_energy, numeric_model, potential_energy, rnea
from support.generated import BACKENDS, generated as generate_all
from support.reference import pin_q_order
from support.extras import need

FUNCTIONS = ("regressor", "inertial_parameters", "base_regressor", "base_parameters",
             "kinetic_energy_regressor", "potential_energy_regressor", "inverse_dynamics")

#: Drives of the planar arm (scene below) and the actuator terms they give each joint row:
#: armature a q̈ + viscous d q̇ + Coulomb f sign q̇ (joint 2: a = 50² · 2e-4 = 0.5, d = 0).
ACTUATED_SCENE = """version: 1
actuators:
  joint1: {armature: 0.3, damping: 0.5, friction: 1.0}
  joint2: {rotor_inertia: 2.0e-4, gear_ratio: 50, friction: 0.7}
symbolic: [m2, l1]
"""
ARMATURE, DAMPING, COULOMB = np.array([0.3, 0.5]), np.array([0.5, 0.0]), np.array([1.0, 0.7])


def generated(model, backends, folder, functions=FUNCTIONS) -> tuple[dict, dict]:
    """``({backend: call}, {backend: module namespace})``: see :mod:`generated`."""
    return generate_all(model, functions, folder, backends)


def states(n: int, count: int = 3, seed: int = 11):
    return random_states(seed, n, count)


def rank(W: np.ndarray) -> int:
    """Numerical rank by SVD, relative tolerance 1e-9 of the largest singular value."""
    s = np.linalg.svd(W, compute_uv=False)
    return int(np.sum(s > 1e-9 * s[0]))


@pytest.fixture(scope="module")
def actuated_arm(tmp_path_factory):
    folder = tmp_path_factory.mktemp("actuated")
    (folder / "drives.yaml").write_text(ACTUATED_SCENE)
    model = eomgen.apply_scene(eomgen.load(eomgen.example_path("planar_2link")),
                               eomgen.load_scene(folder / "drives.yaml"))[0]
    return (model, *generated(model, BACKENDS, folder))


def test_every_backend_gives_Y_pi_equal_to_newton_euler_with_drives(actuated_arm):
    model, calls, modules = actuated_arm
    n = model.dof
    nm = numeric_model(model)
    zero = np.zeros(n)
    names = modules["numpy"]["PARAMETER_NAMES"]
    assert len(names) == 10 * n + 3 * n
    assert tuple(names[10 * n:]) == ("IA1", "IA2", "FV1", "FV2", "FC1", "FC2")
    b = len(modules["numpy"]["BASE_PARAMETER_NAMES"])
    for backend, call in calls.items():
        pi, beta = call("inertial_parameters"), call("base_parameters")
        assert pi.shape == (len(names),) and beta.shape == (b,), backend
        P0 = potential_energy(nm, zero) - call("potential_energy_regressor", zero) @ pi
        stack, base_stack = [], []
        for q, qd, qdd in states(n, 6):
            Y, Y_base = call("regressor", q, qd, qdd), call("base_regressor", q, qd, qdd)
            stack.append(Y)
            base_stack.append(Y_base)
            drives = ARMATURE * qdd + DAMPING * qd + COULOMB * np.sign(qd)
            np.testing.assert_allclose(Y @ pi, rnea(nm, q, qd, qdd) + drives, rtol=1e-12,
                                       atol=1e-12, err_msg=backend)
            np.testing.assert_allclose(Y @ pi, call("inverse_dynamics", q, qd, qdd) + drives,
                                       rtol=1e-12, atol=1e-12, err_msg=backend)
            np.testing.assert_allclose(Y_base @ beta, Y @ pi, rtol=1e-12, atol=1e-12,
                                       err_msg=backend)
            assert call("kinetic_energy_regressor", q, qd) @ pi == pytest.approx(
                kinetic_energy(nm, q, qd), rel=1e-12), backend
            assert call("potential_energy_regressor", q) @ pi + P0 == pytest.approx(
                potential_energy(nm, q), rel=1e-12, abs=1e-12), backend
        # the base columns span what Y spans, independently: rank Y_base = b = rank Y
        assert rank(np.vstack(base_stack)) == b == rank(np.vstack(stack)), backend


def test_parameters_kept_symbolic_are_keywords_of_pi_and_beta(actuated_arm):
    """m2 and l1 stay symbolic (the scene): π(m2, l1) and β(m2, l1) follow them, β exactly (the
    closed-form grouping keeps l1 a symbol)."""
    model, calls, _ = actuated_arm
    values = {"m2": 2.5, "l1": 0.7}
    nm = numeric_model(model, values)
    for backend, call in calls.items():
        pi = call("inertial_parameters", **values)
        beta = call("base_parameters", **values)
        for q, qd, qdd in states(model.dof, 2, seed=5):
            drives = ARMATURE * qdd + DAMPING * qd + COULOMB * np.sign(qd)
            expected = rnea(nm, q, qd, qdd) + drives
            np.testing.assert_allclose(call("regressor", q, qd, qdd, **values) @ pi, expected,
                                       rtol=1e-12, err_msg=backend)
            np.testing.assert_allclose(call("base_regressor", q, qd, qdd, **values) @ beta,
                                       expected, rtol=1e-12, err_msg=backend)


def test_a_batch_of_states_gives_a_batch_of_regressors(actuated_arm):
    model, calls, _ = actuated_arm
    q, qd, qdd = (np.array(x) for x in zip(*states(model.dof, 4)))
    for backend in sorted(set(calls) - {"casadi"}):  # CasADi: one state per call
        batch = calls[backend]("base_regressor", q, qd, qdd)
        single = [calls[backend]("base_regressor", *x) for x in zip(q, qd, qdd)]
        np.testing.assert_allclose(batch, np.array(single), rtol=1e-14, err_msg=backend)


# ----------------------------------------------------------------------------------------------
# UR5: Pinocchio column by column; Panda: the base regressor's size
# ----------------------------------------------------------------------------------------------

def load_urdf(relative: str):
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnsupportedFeatureWarning)  # Panda's finger <mimic>
        return eomgen.load(robots / relative, couplings=False), robots / relative


def test_ur5_regressor_is_pinocchios_column_by_column(tmp_path):
    pin = need("pinocchio")
    model, path = load_urdf("ur_description/urdf/ur5_robot.urdf")
    calls, modules = generated(model, ("numpy", "casadi"), tmp_path)
    pmodel = pin.buildModelFromUrdf(str(path))
    data = pmodel.createData()
    perm = pin_q_order(model, pmodel)  # pinocchio coordinate k is our joint perm[k]
    cols = np.concatenate([np.arange(10) + 10 * perm[k] for k in range(model.dof)])
    pi_pin = np.concatenate([pmodel.inertias[i].toDynamicParameters()
                             for i in range(1, pmodel.njoints)])
    assert len(modules["numpy"]["PARAMETER_NAMES"]) == 60
    assert len(modules["numpy"]["BASE_PARAMETER_NAMES"]) == 36  # the published count
    for backend, call in calls.items():
        pi, beta = call("inertial_parameters"), call("base_parameters")
        np.testing.assert_allclose(pi[cols], pi_pin, rtol=1e-12, atol=1e-14, err_msg=backend)
        base_stack = []
        for q, qd, qdd in states(model.dof, 10):  # 60 rows for 36 base columns
            Y = call("regressor", q, qd, qdd)
            Y_pin = pin.computeJointTorqueRegressor(pmodel, data, q[perm], qd[perm], qdd[perm])
            # our URDF parser snaps rotation entries within 1e-11 of 0/±1, Pinocchio does not
            np.testing.assert_allclose(Y[np.ix_(perm, cols)], Y_pin, rtol=0,
                                       atol=1e-9 * np.abs(Y_pin).max(), err_msg=backend)
            tau = call("inverse_dynamics", q, qd, qdd)
            np.testing.assert_allclose(Y @ pi, tau, rtol=1e-10, atol=1e-10, err_msg=backend)
            Y_base = call("base_regressor", q, qd, qdd)
            base_stack.append(Y_base)
            np.testing.assert_allclose(Y_base @ beta, tau, rtol=1e-10, atol=1e-10,
                                       err_msg=backend)
        assert rank(np.vstack(base_stack)) == 36, backend


def test_panda_base_regressor_is_small_and_has_the_published_count():
    """Panda arm (fingers locked): 43 inertial base parameters (Gaz et al., RA-L 2019), plus the
    7 viscous ones of the URDF's ``<dynamics damping>``, and a generated base regressor within
    the issue's 2,700 operations."""
    from eomgen.codegen import make_job

    panda, _ = load_urdf("panda_description/urdf/panda.urdf")
    scene = ROOT / "examples/scenes/panda_fingers_locked.yaml"
    model = eomgen.apply_scene(panda, eomgen.load_scene(scene))[0]
    dyn = eomgen.derive(model, outputs=["Y", "Y_base", "beta"], simplify=False)
    job = make_job(dyn, ["regressor", "base_regressor", "base_parameters"])
    names = dict(job.constants)["BASE_PARAMETER_NAMES"]
    assert len([n for n in names if not n.startswith("FV")]) == 43
    assert [n for n in names if n.startswith("FV")] == [f"FV{k}" for k in range(1, 8)]
    ops = {s.name: s.operation_count for s in job.specs}
    assert ops["base_regressor"] <= 2700
    assert ops["base_regressor"] < ops["regressor"]


# ----------------------------------------------------------------------------------------------
# The command line
# ----------------------------------------------------------------------------------------------

def test_cli_generates_the_regressor_outputs_and_refuses_a_flexible_joint(tmp_path):
    from click.testing import CliRunner

    from eomgen.cli import main

    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["generate", "--backend", "numpy", "--outputs",
                                       "regressor,pi,base_regressor,beta", "-o", str(out),
                                       "--no-cache", "--quiet"])
    assert result.exit_code == 0, result.output
    spec = importlib.util.spec_from_file_location("cli_regressor", out / "planar_2link_numpy.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert not hasattr(module, "mass_matrix")
    assert module.PARAMETER_NAMES[:2] == ("M1", "MX1") and len(module.PARAMETER_NAMES) == 20
    nm = numeric_model(eomgen.load(eomgen.example_path("planar_2link")))
    for q, qd, qdd in states(2, 2):
        tau = rnea(nm, q, qd, qdd)
        np.testing.assert_allclose(module.regressor(q, qd, qdd) @ module.inertial_parameters(),
                                   tau, rtol=1e-12)
        np.testing.assert_allclose(module.base_regressor(q, qd, qdd) @ module.base_parameters(),
                                   tau, rtol=1e-12)

    flexible = ROOT / "examples/robots/flexible_2link.yaml"
    bad = tmp_path / "bad"
    result = CliRunner().invoke(main, ["generate", str(flexible), "--backend", "numpy",
                                       "--outputs", "Y", "-o", str(bad), "--no-cache", "--quiet"])
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and "joint 'joint1' actuator: a flexible joint" in lines[0]
    assert not bad.exists()


def test_base_outputs_are_byte_identical_when_generated_again():
    """The base is found by sampling (seeded): generating again, from scratch, gives the same
    bytes."""
    from eomgen.regressor import generated_base

    model = eomgen.load(eomgen.example_path("puma560_arm3"))
    texts = []
    for _ in range(2):
        generated_base.cache_clear()
        files = render_files(model, ["numpy"], functions=["base_regressor", "base_parameters"])
        texts.append(files[0].content)
    assert texts[0] == texts[1] and "BASE_PARAMETER_NAMES" in texts[0]


def test_tilted_axes_take_the_numeric_route(tmp_path):
    """A random tree (tilted revolute axes, prismatic joints, merged fixed links): the
    closed-form grouping does not apply, the numeric route gives the base; Y π is
    eomgen.numeric's Newton–Euler and Y_base β = Y π."""
    from eomgen.regressor import generated_base
    from support.reference import random_robot

    model = random_robot(np.random.default_rng(1), 4, tree=True)
    assert generated_base(model).route == "numeric"
    calls, modules = generated(model, ("numpy",), tmp_path)
    call, nm = calls["numpy"], numeric_model(model)
    pi, beta = call("inertial_parameters"), call("base_parameters")
    base_stack = []
    for q, qd, qdd in states(model.dof, 12):
        tau = rnea(nm, q, qd, qdd)
        np.testing.assert_allclose(call("regressor", q, qd, qdd) @ pi, tau, rtol=1e-10,
                                   atol=1e-10)
        base_stack.append(call("base_regressor", q, qd, qdd))
        np.testing.assert_allclose(base_stack[-1] @ beta, tau, rtol=1e-8, atol=1e-8)
    assert rank(np.vstack(base_stack)) == len(beta) == len(modules["numpy"]["BASE_PARAMETER_NAMES"])


def test_a_model_too_large_to_write_out_has_its_regressor_generated_as_the_docs_say(tmp_path):
    """Issue 29: docs/regressor.md said the Y of models beyond the textbook bound "is printed by
    no backend yet"; `eomgen generate --outputs regressor` prints it for the 6-joint PUMA, and
    the LaTeX document's sentence points to eomgen.regressor."""
    from support import DOCS, run_in_process

    from eomgen.symbolic.textbook import TEXTBOOK_MAX_DOF

    puma = eomgen.example_path("puma560_dh")
    out = tmp_path / "out"
    result = run_in_process("generate", puma, "--backend", "numpy", "--outputs",
                            "regressor,pi", "-o", out, "--no-cache", "--quiet")
    assert result.returncode == 0, result.stderr
    module = load_module_file(out / "puma560_numpy.py")
    assert len(module.PARAMETER_NAMES) > 6 * 10 - 1 and 6 > TEXTBOOK_MAX_DOF
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # PUMA link 1 is not a physical body (see its file)
        nm = numeric_model(eomgen.load(puma))
    for q, qd, qdd in states(6, 2):
        np.testing.assert_allclose(module.regressor(q, qd, qdd) @ module.inertial_parameters(),
                                   rnea(nm, q, qd, qdd), rtol=1e-10, atol=1e-12)
    text = (DOCS / "regressor.md").read_text(encoding="utf-8")
    assert "no backend" not in text and "every code backend prints it" in text


def load_module_file(path):
    spec = importlib.util.spec_from_file_location(path.stem + "_docs", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
