"""What ``eomgen generate`` writes imports as its last stderr line says: no two files of one output
folder import under one name (the C backend's shared library once hid the CasADi module:
``planar_2link_casadi.so`` beside ``planar_2link_casadi.py``), and the hint names every module."""

from __future__ import annotations

import importlib.util
import json
import re
import subprocess
import sys

import pytest

import eomgen
from eomgen.codegen import available_backends
from eomgen.common.compiler import c_compiler
from eomgen.common.output import import_collisions, python_module_name
from support import run_in_process
from support.extras import need

STEM = "planar_2link"

# in a fresh interpreter: import every module the hint names from the folder alone, and give
# M of the CasADi and NumPy modules at one state
CHILD = """
import importlib, json, sys
import numpy as np
folder, modules = sys.argv[1], sys.argv[2:]
sys.path.insert(0, folder)
files = {m: importlib.import_module(m).__file__ for m in modules}
import planar_2link_casadi, planar_2link_numpy
q = np.array([0.3, -0.7])
print(json.dumps({"files": files,
                  "casadi": np.array(planar_2link_casadi.mass_matrix(q=q)["M"]).tolist(),
                  "numpy": planar_2link_numpy.mass_matrix(q).tolist()}))
"""


@pytest.mark.slow
def test_every_module_of_the_default_output_imports_as_the_hint_says(tmp_path):
    need("casadi", reason="the CasADi module is imported")
    folder = tmp_path / "out"
    done = run_in_process("generate", eomgen.example_path("planar_2link"), "-o", folder,
                          "--cache-dir", tmp_path / "cache")
    assert done.returncode == 0, done.stderr
    names = sorted(p.name for p in folder.iterdir())
    assert import_collisions(names) == []
    if c_compiler() is not None:
        assert "libplanar_2link_casadi.so" in names and "planar_2link_casadi.so" not in names

    hint = done.stderr.splitlines()[-1]
    found = re.fullmatch(r"eomgen: to import, put the folder on the path, sys\.path\.insert\(0, "
                         r"'(.*)'\), then import (\w+)(?: \(also ([\w, ]+)\))?; "
                         r"--name STEM names them STEM_\*", hint)
    assert found, hint
    assert found[1] == str(folder)
    hinted = [found[2], *(found[3].split(", ") if found[3] else [])]
    # every .py file and extension module written, and nothing else
    assert sorted(hinted) == sorted({python_module_name(n) for n in names} - {None})
    python_backends = {"numpy", "casadi", "jax", "torch"} & set(available_backends())
    assert {f"{STEM}_{b}" for b in python_backends} <= set(hinted)

    # the JAX and PyTorch modules are written without their extras, and import them
    needs = {f"{STEM}_jax": "jax", f"{STEM}_torch": "torch"}
    hinted = [m for m in hinted if m not in needs or importlib.util.find_spec(needs[m])]
    child = subprocess.run([sys.executable, "-c", CHILD, str(folder), *hinted],
                           capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert child.returncode == 0, child.stderr
    result = json.loads(child.stdout)
    # each module came from its own file of the folder (not a shadowing library)
    assert {m: f.rsplit("/", 1)[-1] for m, f in result["files"].items()} == {
        m: next(n for n in names if python_module_name(n) == m) for m in hinted}
    assert result["files"][f"{STEM}_casadi"].endswith(f"{STEM}_casadi.py")
    # the CasADi module's M against the NumPy module's, and against the closed form of the
    # planar arm's mass matrix (m = 1, l = 1, lc = 0.5, I = 1/12 in the description)
    import numpy as np

    q2 = -0.7
    m11 = 1 / 12 + 1 / 12 + 0.25 + 1 + 0.25 + 2 * 0.5 * np.cos(q2)
    m12 = 1 / 12 + 0.25 + 0.5 * np.cos(q2)
    closed = np.array([[m11, m12], [m12, 1 / 12 + 0.25]])
    np.testing.assert_allclose(result["casadi"], result["numpy"], rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(result["casadi"], closed, rtol=1e-13, atol=1e-13)
