"""The O(n) outputs in generated modules (issue 18): ``forward_dynamics_aba(q, qd, tau)`` by the
Articulated-Body Algorithm and ``nonlinear_effects(q, qd)`` = C q̇ + g by one Newton–Euler pass,
printed by every backend and compared with independent computations:

* Pinocchio's ``pin.aba`` and ``pin.nonLinearEffects`` on a random tree with prismatic joints and
  fixed links (built joint by joint, :func:`reference.to_pinocchio`);
* the same module's Cholesky ``forward_dynamics`` and ``inverse_dynamics(q, qd, 0)``;
* the planar arm with its parameters symbolic: keyword arguments change the result as the
  numeric Newton–Euler of :mod:`eomgen.numeric` says.
"""

from __future__ import annotations


import numpy as np

import eomgen
from eomgen.codegen.functions import select_functions
from eomgen.numeric import M_rnea, numeric_model, rnea
from support.generated import generated
from support.reference import pin_q_order, random_robot, to_pinocchio
from support.extras import need

FUNCTIONS = select_functions(["qdd_aba", "h", "forward_dynamics"])


def load_modules(model, folder):
    """{backend: get(name) -> function returning NumPy arrays} of every backend (the functions
    of :mod:`generated`, called positionally or by name alike)."""
    calls = generated(model, FUNCTIONS, folder)[0]
    return {backend: (lambda name, call=call: (lambda *args, **kwargs: call(name, *args, **kwargs)))
            for backend, call in calls.items()}


def test_aba_and_nonlinear_effects_agree_with_pinocchio_in_every_backend(tmp_path):
    pin = need("pinocchio", reason="Pinocchio is the reference")
    model = random_robot(np.random.default_rng(4), 5, tree=True)
    pmodel = to_pinocchio(model)
    data = pmodel.createData()
    perm = pin_q_order(model, pmodel)
    inv = np.argsort(perm)
    modules = load_modules(model, tmp_path)
    rng = np.random.default_rng(11)
    for _ in range(3):
        q, qd, tau = (rng.uniform(-1.5, 1.5, model.dof) for _ in range(3))
        expected_qdd = np.asarray(pin.aba(pmodel, data, q[perm], qd[perm], tau[perm]))[inv]
        expected_h = np.asarray(pin.nonLinearEffects(pmodel, data, q[perm], qd[perm]))[inv]
        scale_qdd, scale_h = max(1, np.abs(expected_qdd).max()), max(1, np.abs(expected_h).max())
        for backend, get in modules.items():
            qdd = get("forward_dynamics_aba")(q, qd, tau)
            h = get("nonlinear_effects")(q, qd)
            assert np.abs(qdd - expected_qdd).max() <= 1e-10 * scale_qdd, backend
            assert np.abs(h - expected_h).max() <= 1e-10 * scale_h, backend
    # within the module: the ABA equals the Cholesky route, h equals tau(q, qd, 0), on a batch
    numpy = modules["numpy"]
    Q, QD, TAU = (rng.uniform(-1.5, 1.5, (6, model.dof)) for _ in range(3))
    np.testing.assert_allclose(numpy("forward_dynamics_aba")(Q, QD, TAU),
                               numpy("forward_dynamics")(Q, QD, TAU), rtol=1e-9, atol=1e-10)
    np.testing.assert_allclose(numpy("nonlinear_effects")(Q, QD),
                               numpy("inverse_dynamics")(Q, QD, np.zeros_like(Q)),
                               rtol=1e-10, atol=1e-10)


def test_symbolic_parameters_are_keywords_of_the_aba(tmp_path):
    model = eomgen.load(eomgen.example_path("planar_2link"))
    module = load_modules(model, tmp_path)["numpy"]
    values = {p.name: p.value for p in model.parameters} | {"m2": 2.5, "l1": 0.7}
    nm = numeric_model(model.substitute({p.symbol: values[p.name] for p in model.parameters}))
    q, qd, tau = np.array([0.3, -0.8]), np.array([1.1, 0.4]), np.array([2.0, -1.0])
    M = M_rnea(nm, q)
    expected = np.linalg.solve(M, tau - rnea(nm, q, qd, np.zeros(2)))
    np.testing.assert_allclose(module("forward_dynamics_aba")(q, qd, tau, m2=2.5, l1=0.7),
                               expected, rtol=1e-12)
    np.testing.assert_allclose(module("nonlinear_effects")(q, qd, m2=2.5, l1=0.7),
                               rnea(nm, q, qd, np.zeros(2)), rtol=1e-12)


def test_cli_generates_the_aba_on_request(tmp_path):
    from click.testing import CliRunner

    from eomgen.cli import main

    result = CliRunner().invoke(main, ["generate", "--backend", "numpy", "--outputs",
                                       "forward_dynamics_aba,h", "-o", str(tmp_path / "out"),
                                       "--no-cache", "--quiet"])
    assert result.exit_code == 0, result.output
    text = (tmp_path / "out" / "planar_2link_numpy.py").read_text()
    assert "def forward_dynamics_aba(q, qd, tau, *" in text
    assert "def nonlinear_effects(q, qd, *" in text and "def mass_matrix(" not in text
