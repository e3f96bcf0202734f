"""Shared by the tests of the array backends (tests/backends/test_backend_jax.py,
test_backend_torch.py): each backend's module generated next to the NumPy module, which is the reference (itself checked
against Newton–Euler and Pinocchio in test_codegen).

Robots: the bundled planar arm (all parameters symbolic) and PUMA 560, the UR5 and the Panda
(fingers locked; example-robot-data, skipped with a reason when missing).
"""

from __future__ import annotations

import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import eomgen
from eomgen.codegen.generate import generate
from eomgen.codegen.scene_generate import generate_scene
from eomgen.scene import load_scene
from support import ROOT, erd_robots_dir, load_module  # noqa: F401  (load_module: re-export)

FUNCTIONS = ("mass_matrix", "coriolis_matrix", "gravity_vector", "inverse_dynamics",
             "forward_dynamics")
ARGUMENTS = {"mass_matrix": 1, "coriolis_matrix": 2, "gravity_vector": 1,
             "inverse_dynamics": 3, "forward_dynamics": 3}
ROBOTS = ("planar_2link", "puma560", "ur5", "panda")


def generate_robot(name: str, outdir: Path, backends: str) -> list[Path]:
    """The files of robot ``name`` (one of :data:`ROBOTS`) for ``backends`` in ``outdir``."""
    if name in ("planar_2link", "puma560"):
        path = eomgen.example_path("planar_2link" if name == "planar_2link" else "puma560_dh")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # PUMA 560's published inertias warn by design
            return generate(eomgen.load(path), outdir, backends, cache=False)
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    if name == "ur5":
        return generate(eomgen.load(robots / "ur_description/urdf/ur5_robot.urdf"), outdir,
                        backends, cache=False)
    scene = load_scene(ROOT / "examples/scenes/panda_fingers_locked.yaml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the fingers' <mimic>: locked by the scene anyway
        model = eomgen.load(robots / "panda_description/urdf/panda.urdf")
    paths, _ = generate_scene(model, scene, outdir, backends)
    return paths


def robot_modules(kind: str, tmp_path_factory):
    """``get(name)``: robot ``name``'s ``numpy`` and ``kind`` modules (attributes of one
    namespace), generated once per test module."""
    built: dict[str, SimpleNamespace] = {}

    def get(name: str) -> SimpleNamespace:
        if name not in built:
            paths = generate_robot(name, tmp_path_factory.mktemp(name), f"numpy,{kind}")
            modules = {}
            for backend in ("numpy", kind):
                path = next(p for p in paths if p.name.endswith(f"_{backend}.py"))
                modules[backend] = load_module(path, f"{name}_{backend}_under_test")
            built[name] = SimpleNamespace(**modules)
        return built[name]

    return get


def states(n: int, count: int = 5, seed: int = 0):
    rng = np.random.default_rng(seed)
    return (rng.uniform(-np.pi, np.pi, (count, n)), rng.normal(size=(count, n)),
            rng.normal(size=(count, n)))


def assert_relative(actual, expected, tol=1e-12, what=""):
    actual, expected = np.asarray(actual), np.asarray(expected)
    assert actual.shape == expected.shape, (what, actual.shape, expected.shape)
    scale = max(float(np.max(np.abs(expected))), np.finfo(float).tiny)
    error = float(np.max(np.abs(actual - expected))) / scale
    assert error <= tol, f"{what}: relative error {error:.2e} > {tol:.0e}"


def central_difference(f, x, h=1e-6):
    """d f / d x of a scalar function of a vector, by central differences (error ~ h^2)."""
    out = np.zeros_like(x)
    for i in range(x.size):
        e = np.zeros_like(x)
        e[i] = h
        out[i] = (f(x + e) - f(x - e)) / (2 * h)
    return out


def hostile_modules(kind: str) -> dict:
    """The NumPy and ``kind`` modules of a robot whose names try to break out of strings,
    executed after checking that their names stay text and that each imports only its own
    framework: ``{"numpy": namespace, kind: namespace}``."""
    import ast

    from eomgen.codegen.generate import render_files
    from support.robots import DOCSTRING_BREAKER, HOSTILE, hostile_star

    files = {f.name: f.content for f in render_files(hostile_star(DOCSTRING_BREAKER),
                                                     ["numpy", kind])}
    assert len(files) == 2
    modules = {}
    for name, content in files.items():
        tree = ast.parse(content)
        assert repr(DOCSTRING_BREAKER) in ast.get_docstring(tree)
        imports = {alias.name for node in ast.walk(tree)
                   if isinstance(node, (ast.Import, ast.ImportFrom)) for alias in node.names}
        backend = name.rsplit("_", 1)[1][:-3]
        assert imports - {"warnings"} <= {"numpy", "cho_solve"} | (
            set() if backend == "numpy" else {backend, f"{backend}.numpy"}), (backend, imports)
        namespace: dict = {}
        exec(compile(content, name, "exec"), namespace)  # noqa: S102 - our generated code
        assert namespace["JOINT_NAMES"] == HOSTILE
        modules[backend] = namespace
    return modules
