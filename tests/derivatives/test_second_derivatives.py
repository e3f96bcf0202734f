"""Second derivatives of the inverse dynamics as generated outputs (issue 42):
``inverse_dynamics_second_derivatives`` and its four tensors in every code backend.

References, each independent of the second-order forward-mode program: central differences of
the generated first derivatives (∂τ/∂q, ∂τ/∂q̇ and M; NumPy); Pinocchio's C++
``ComputeRNEASecondOrderDerivatives`` (the header of the ``pin`` wheel compiled once per module,
Eigen from ``cmeel-eigen``) on the Panda and a random tree with prismatic joints; and the
module's backends against each other.
"""

from __future__ import annotations

import shutil
import subprocess
import sysconfig
from pathlib import Path

import numpy as np
import pytest

import eomgen
from eomgen.codegen.backends.casadi_backend import c_compiler, library_name
from eomgen.codegen.functions import module_name
from eomgen.codegen.generate import render_files
from eomgen.errors import UnsupportedError
from eomgen.outputs import OUTPUTS
from support import robots
from support.generated import generated
from support.extras import need
from support.reference import pin_q_order, random_robot, to_pinocchio

COMBINED = "inverse_dynamics_second_derivatives"
SINGLE = ["inverse_dynamics_second_derivative_q", "inverse_dynamics_second_derivative_qd",
          "inverse_dynamics_second_derivative_q_qd", "mass_matrix_derivative_q"]
FIRST = ["inverse_dynamics_derivatives", "mass_matrix"]


def results(backend, module, function, *inputs) -> tuple:
    """The function's results as a tuple of float arrays (a CasADi function by name)."""
    declared = OUTPUTS[function]
    if backend == "casadi":
        out = module[function].call(dict(zip(declared.inputs, inputs)))
        return tuple(np.array(out[s], dtype=float) for s in (declared.returns or
                                                              (declared.symbol,)))
    out = module[function](*inputs)
    return tuple(np.asarray(x, dtype=float) for x in (out if declared.returns else (out,)))


def tensors(backend, module, q, qd, qdd) -> list[np.ndarray]:
    """The four tensors (n, n, n) of the combined function."""
    n = q.size
    return [x.reshape(n, n, n) for x in results(backend, module, COMBINED, q, qd, qdd)]


@pytest.fixture(scope="module")
def scara(tmp_path_factory):
    """The SCARA (revolute, revolute, prismatic) in every code backend."""
    model = eomgen.load(eomgen.example_path("scara_rrp"))
    _, modules = generated(model, [COMBINED, *SINGLE, *FIRST], tmp_path_factory.mktemp("scara"))
    return model, modules


def _state(seed: int, n: int) -> tuple:
    rng = np.random.default_rng(seed)
    return tuple(rng.uniform(-1.2, 1.2, n) for _ in range(3))


def central_difference(f, x, h=1e-6):
    """∂f/∂x by central differences, the direction as the last index."""
    columns = []
    for k in range(x.size):
        e = np.zeros_like(x)
        e[k] = h
        columns.append((f(x + e) - f(x - e)) / (2 * h))
    return np.stack(columns, axis=-1)


def relative(a, b) -> float:
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


def test_second_derivatives_are_central_differences_of_the_first(scara):
    model, modules = scara
    m, n = modules["numpy"], model.dof
    for seed in (1, 2):
        q, qd, qdd = _state(seed, n)
        qq, vv, qv, aq = tensors("numpy", m, q, qd, qdd)
        assert qq.shape == (n, n, n)
        # [i, j, k]: the first derivative's index j, the second (difference) index k
        assert relative(qq, central_difference(
            lambda x: m[FIRST[0]](x, qd, qdd)[0], q)) < 1e-6
        assert relative(vv, central_difference(
            lambda x: m[FIRST[0]](q, x, qdd)[1], qd)) < 1e-6
        assert relative(qv, central_difference(
            lambda x: m[FIRST[0]](q, x, qdd)[0], qd)) < 1e-6
        assert relative(aq, central_difference(lambda x: m["mass_matrix"](x), q)) < 1e-6
        np.testing.assert_array_equal(qq, qq.transpose(0, 2, 1))  # mirrored, exactly
        np.testing.assert_array_equal(vv, vv.transpose(0, 2, 1))
        assert np.abs(vv).max() > 0 and np.abs(aq).max() > 0


def test_every_backend_and_every_single_function_give_the_same_tensors(scara):
    model, modules = scara
    n = model.dof
    q, qd, qdd = _state(3, n)
    expected = tensors("numpy", modules["numpy"], q, qd, qdd)
    for backend, module in modules.items():
        got = tensors(backend, module, q, qd, qdd)
        for a, b in zip(got, expected):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12, err_msg=backend)
        for function, b in zip(SINGLE, expected):
            inputs = (q,) if OUTPUTS[function].inputs == ("q",) else (q, qd, qdd)
            [single] = results(backend, module, function, *inputs)
            assert single.shape == (n, n * n), (backend, function)
            np.testing.assert_allclose(single.reshape(n, n, n), b, rtol=1e-12, atol=1e-12,
                                       err_msg=f"{backend} {function}")


def test_a_quaternion_free_flyer_is_refused_in_one_line():
    import dataclasses

    from eomgen.reduction import apply_scene
    from eomgen.scene import load_scene
    root = robots.ROOT
    scene = load_scene(root / "examples/contacts/top_on_a_point.yaml")
    model = apply_scene(eomgen.load(root / "examples/robots/spinning_top.yaml"),
                        dataclasses.replace(scene, floating_base="quaternion"))[0]
    assert model.quaternion_joints
    with pytest.raises(UnsupportedError) as error:
        eomgen.derive(model, outputs=["tau", "d2tau"])
    message = str(error.value)
    assert "\n" not in message and "d2tau not derived for a quaternion free flyer" in message


def test_coupled_joints_are_refused_in_one_line():
    from eomgen.model import couple

    arm = eomgen.load(eomgen.example_path("elbow_rrr"))
    geared = couple(arm, "elbow", "shoulder", ratio=-1, offset=0.2)
    with pytest.raises(UnsupportedError) as error:
        eomgen.derive(geared, outputs=["tau", "d2tau_dqdq"])
    message = str(error.value)
    assert "\n" not in message and "d2tau_dqdq not derived for a model with coupled" in message


# --- Pinocchio's C++ ComputeRNEASecondOrderDerivatives ---------------------------------------

#: The program: reads a model of revolute and prismatic joints (any axis) and states from stdin,
#: prints the four tensors of each state, ``T[i][j][k]`` in that order.
SECOND_ORDER_CPP = r"""
#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/rnea-second-order-derivatives.hpp>
#include <cstdio>
#include <iostream>
#include <string>

int main()
{
    pinocchio::Model model;
    int joints, states;
    std::cin >> joints;
    for (int j = 0; j < joints; ++j) {
        int parent; std::string kind; Eigen::Vector3d axis, p, c; Eigen::Matrix3d R, I;
        double m;
        std::cin >> parent >> kind;
        for (int k = 0; k < 3; ++k) std::cin >> axis[k];
        for (int k = 0; k < 9; ++k) std::cin >> R(k / 3, k % 3);
        for (int k = 0; k < 3; ++k) std::cin >> p[k];
        std::cin >> m;
        for (int k = 0; k < 3; ++k) std::cin >> c[k];
        for (int k = 0; k < 9; ++k) std::cin >> I(k / 3, k % 3);
        pinocchio::SE3 placement(R, p);
        std::string name = "j" + std::to_string(j);
        pinocchio::Model::JointIndex id = kind == "R"
            ? model.addJoint(parent, pinocchio::JointModelRevoluteUnaligned(axis), placement, name)
            : model.addJoint(parent, pinocchio::JointModelPrismaticUnaligned(axis), placement, name);
        model.appendBodyToJoint(id, pinocchio::Inertia(m, c, I), pinocchio::SE3::Identity());
    }
    Eigen::Vector3d g;
    for (int k = 0; k < 3; ++k) std::cin >> g[k];
    model.gravity.linear(g);
    const int n = model.nv;
    std::cin >> states;
    for (int s = 0; s < states; ++s) {
        Eigen::VectorXd q(n), v(n), a(n);
        for (int k = 0; k < n; ++k) std::cin >> q[k];
        for (int k = 0; k < n; ++k) std::cin >> v[k];
        for (int k = 0; k < n; ++k) std::cin >> a[k];
        pinocchio::Data data(model);  /* a fresh Data per call (notes/pinocchio-cpp.md) */
        pinocchio::ComputeRNEASecondOrderDerivatives(model, data, q, v, a);
        for (int t = 0; t < 4; ++t)
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j)
                    for (int k = 0; k < n; ++k)
                        printf("%.17g\n", t == 0 ? data.d2tau_dqdq(i, j, k)
                               : t == 1 ? data.d2tau_dvdv(i, j, k)
                               : t == 2 ? data.d2tau_dqdv(i, j, k) : data.d2tau_dadq(i, j, k));
    }
    return 0;
}
"""
DEFINES = ["-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", "-DBOOST_MPL_LIMIT_LIST_SIZE=30",
           "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30", "-DBOOST_FUSION_INVOKE_MAX_ARITY=12"]


@pytest.fixture(scope="module")
def pinocchio_second_order(tmp_path_factory) -> Path:
    """The compiled program (header-only Pinocchio, -O1: about a minute on two cores)."""
    include = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix" / "include"
    if shutil.which("g++") is None:
        pytest.skip("needs a C++ compiler (g++)")
    if not (include / "eigen3").is_dir() or not (include / "pinocchio").is_dir():
        pytest.skip("needs Pinocchio's headers (pin) and Eigen's (pip install -e '.[bench]' brings cmeel-eigen)")
    folder = tmp_path_factory.mktemp("pinocchio_second_order")
    (folder / "second.cpp").write_text(SECOND_ORDER_CPP, encoding="utf-8")
    subprocess.run(["g++", "-O1", "-std=c++17", *DEFINES, f"-I{include}",
                    f"-I{include / 'eigen3'}", "second.cpp", "-o", "second"], cwd=folder,
                   check=True)
    return folder / "second"


def _numbers(values) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(values))


def pinocchio_tensors(program: Path, pm, states) -> list[list[np.ndarray]]:
    """The four tensors of Pinocchio's ``ComputeRNEASecondOrderDerivatives`` at each state
    (Pinocchio's coordinates) of ``pm``, a model of unaligned revolute/prismatic joints."""
    lines = [str(pm.njoints - 1)]
    for j in range(1, pm.njoints):
        joint, M, Y = pm.joints[j], pm.jointPlacements[j], pm.inertias[j]
        kind = "R" if "Revolute" in joint.shortname() else "P"
        lines.append(" ".join([str(pm.parents[j]), kind, _numbers(joint.extract().axis),
                               _numbers(M.rotation), _numbers(M.translation), repr(Y.mass),
                               _numbers(Y.lever), _numbers(Y.inertia)]))
    lines += [_numbers(pm.gravity.linear), str(len(states))]
    lines += [_numbers(np.concatenate(s)) for s in states]
    out = subprocess.run([str(program)], input="\n".join(lines) + "\n", capture_output=True,
                         text=True, check=True).stdout
    n = pm.nv
    values = np.array(out.split(), dtype=float).reshape(len(states), 4, n, n, n)
    return [list(v) for v in values]


@pytest.mark.slow
@pytest.mark.parametrize("which", ["panda", "random_tree"])
def test_second_derivatives_equal_pinocchios_cpp(which, pinocchio_second_order, tmp_path):
    if which == "panda":
        model = robots.panda()
    else:
        model = random_robot(np.random.default_rng(13), 5, tree=True, prismatic=True)
        assert any(not j.type.is_revolute for j in model.joints if j.type.is_movable)
    _, modules = generated(model, [COMBINED], tmp_path, backends=("numpy",))
    pm = to_pinocchio(model)
    perm = pin_q_order(model, pm)
    inv = np.argsort(perm)
    n = model.dof
    states = [_state(seed, n) for seed in (5, 6)]
    theirs = pinocchio_tensors(pinocchio_second_order, pm,
                               [tuple(x[perm] for x in s) for s in states])
    for state, expected in zip(states, theirs):
        ours = tensors("numpy", modules["numpy"], *state)
        for what, a, b in zip(("d2tau_dqdq", "d2tau_dvdv", "dtau_dqdv", "dtau_dadq"), ours,
                              expected):
            b = b[np.ix_(inv, inv, inv)]
            assert relative(a, b) < 1e-9, (which, what, relative(a, b))


def test_the_c_backends_library_gives_the_numpy_modules_tensors(scara, tmp_path):
    """The ``c`` backend (CasADi's C, a shared library) through ``casadi.external``."""
    casadi = need("casadi")
    if c_compiler() is None:
        pytest.skip("needs a C compiler")
    model, modules = scara
    n = model.dof
    for f in render_files(model, ["c"], functions=[COMBINED]):
        path = tmp_path / f.name
        path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
            f.content, encoding="utf-8")
    function = casadi.external(COMBINED, str(tmp_path / library_name(module_name(model.name))))
    q, qd, qdd = _state(7, n)
    out = function.call({"q": q, "qd": qd, "qdd": qdd})
    for symbol, b in zip(OUTPUTS[COMBINED].returns, tensors("numpy", modules["numpy"], q, qd,
                                                            qdd)):
        np.testing.assert_allclose(np.array(out[symbol]).reshape(n, n, n), b, rtol=1e-12,
                                   atol=1e-12, err_msg=symbol)
