"""The corpus of bad and hostile inputs (``tests/corpus/``, described by its ``expected.yaml``).

For each bad file: :func:`eomgen.load` raises exactly the listed subclass of
:class:`~eomgen.errors.DescriptionError`, with a one-line message naming the file, the element
and the problem; ``eomgen generate FILE -o DIR`` exits with code 2, prints that one line on
stderr (warnings aside) and writes nothing. For each hostile but valid file: every backend
generates, and the generated Python modules parse and import, their ``JOINT_NAMES`` holding the
hostile names unchanged.

Most command runs are in process (click's CliRunner); a few files also run as real
``python -m eomgen.cli`` processes.
"""

from __future__ import annotations

import ast
import importlib.util
import inspect
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml

import eomgen
from support import CORPUS, ERROR, WARNING, load_module, run_cli as run
from eomgen.codegen import available_backends
from eomgen import errors
from eomgen.codegen.functions import parameter_arguments
from eomgen.dynamics import derive

EXPECTED = yaml.safe_load((CORPUS / "expected.yaml").read_text(encoding="utf-8"))
BAD: dict[str, dict] = EXPECTED["bad"]
VALID: dict[str, dict] = EXPECTED["valid"]


def error_lines(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if not line.startswith(WARNING)]


def expected_start(path: Path, case: dict) -> str:
    element = case.get("element")
    return f"{path}: {element}" if element else f"{path}: "


# ----------------------------------------------------------------------------------------------
# The corpus itself
# ----------------------------------------------------------------------------------------------

def test_every_file_is_described_once_and_every_error_class_is_exercised():
    files = {p.name for p in CORPUS.iterdir()} - {"expected.yaml", "README.md"}
    assert files == set(BAD) | set(VALID)
    assert not set(BAD) & set(VALID)
    assert len(BAD) >= 40
    used = {case["error"] for case in BAD.values()}
    for name in used:
        assert issubclass(getattr(errors, name), errors.DescriptionError), name
    defined = {name for name, cls in inspect.getmembers(errors, inspect.isclass)
               if issubclass(cls, errors.DescriptionError) and cls is not errors.DescriptionError}
    defined -= {"SceneError"}  # scene files, not descriptions: tested with the scenes
    # loops are a scene's or an MJCF file's (MuJoCo, an extra this corpus does not need):
    # tests/loops/test_loop_checks.py raises it from both
    defined -= {"InvalidLoopError"}
    assert defined <= used, f"error classes no corpus file raises: {sorted(defined - used)}"


# ----------------------------------------------------------------------------------------------
# Bad files: the library
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", sorted(BAD))
def test_load_raises_the_specific_error(name):
    case, path = BAD[name], CORPUS / name
    strict = case.get("strict", False)
    if strict:  # usable by default, with one warning
        with pytest.warns(UserWarning):
            eomgen.load(path)
    started = time.monotonic()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning on the way to the error
        with pytest.raises(errors.EomgenError) as caught:
            eomgen.load(path, strict=strict)
    assert time.monotonic() - started < 5
    assert type(caught.value) is getattr(errors, case["error"]), repr(caught.value)
    message = str(caught.value)
    assert message.startswith(expected_start(path, case)), message
    assert case["message"] in message, message
    assert len(message.splitlines()) == 1
    assert "root:" not in message and "pwned" not in message  # nothing of /etc/passwd or code


# ----------------------------------------------------------------------------------------------
# Bad files: the command line
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", sorted(BAD))
def test_generate_refuses_with_one_line_and_writes_nothing(name, tmp_path, capfd):
    case, path = BAD[name], CORPUS / name
    outdir = tmp_path / "out"
    result = run("generate", path, "-o", outdir, *(["--strict"] if case.get("strict") else []))
    assert result.exit_code == 2, (result.output, result.exception)
    assert result.stdout == ""
    lines = error_lines(result.stderr)
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(ERROR + expected_start(path, case)), lines[0]
    assert case["message"] in lines[0], lines[0]
    assert "Traceback" not in result.stderr
    assert list(tmp_path.iterdir()) == []  # no output folder, no staging folder
    assert "pwned" not in capfd.readouterr().out


#: A few files, run as real processes (one each of the XML, YAML, strict and size paths).
REAL_PROCESS_CASES = ["urdf_xml_billion_laughs.urdf", "urdf_inertia_triangle_inequality.urdf",
             "yaml_python_object_tag.yaml", "yaml_mass_negative.yaml",
             "urdf_too_many_joints.urdf"]


@pytest.mark.slow
def test_generate_in_a_real_process(tmp_path):
    started = {}
    for name in REAL_PROCESS_CASES:
        outdir = tmp_path / name / "out"
        outdir.parent.mkdir()
        command = [sys.executable, "-m", "eomgen.cli", "generate", str(CORPUS / name), "-o",
                   str(outdir)] + (["--strict"] if BAD[name].get("strict") else [])
        started[name] = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                         text=True)
    for name, process in started.items():
        stdout, stderr = process.communicate(timeout=120)
        assert process.returncode == 2, (name, stderr)
        assert stdout == ""
        lines = error_lines(stderr)
        assert len(lines) == 1, (name, stderr)
        assert lines[0].startswith(ERROR + expected_start(CORPUS / name, BAD[name])), lines[0]
        assert list((tmp_path / name).iterdir()) == []


# ----------------------------------------------------------------------------------------------
# Hostile but valid files
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", sorted(VALID))
@pytest.mark.slow
def test_hostile_but_valid_files_generate_with_every_backend(name, tmp_path, capfd):
    path = CORPUS / name
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = eomgen.load(path)
    assert bool(caught) == VALID[name].get("warns", False), [str(w.message) for w in caught]
    outdir = tmp_path / "out"
    result = run("generate", path, "-o", outdir, "--no-cache")
    assert result.exit_code == 0, (result.stderr, result.exception)
    written = {p.name: p for p in outdir.iterdir()}
    assert sorted(Path(line).name for line in result.stdout.splitlines()) == sorted(written)
    suffixes = sorted(p.name.removeprefix(p.name.split("_")[0]) for p in written.values())
    # every backend's main file (its config's suffix after the module stem), whatever the
    # registry holds; the casadi .so and the fast module when compiled
    for backend in available_backends().values():
        assert any(backend.config().suffix in n for n in written), (backend.name, suffixes)
    assert any(n.endswith(".tex") for n in written) and any(n.endswith(".c") for n in written)
    n = model.dof
    for file_name, file in written.items():
        assert file_name.isascii() and "/" not in file_name
        if "_fast." in file_name and not file_name.endswith(".c"):  # the compiled fast module
            stem = file_name.split(".")[0]
            fast = load_module(file, stem)
            assert fast.JOINT_NAMES == model.joint_names and fast.NQ == n
            assert set(fast.PARAMETERS) == {p.keyword for p in parameter_arguments(
                derive(model, outputs=("g",), simplify=False))}
            M = fast.mass_matrix(np.linspace(-1, 1, n))
            assert M.shape == (n, n) and np.all(np.isfinite(M)) and np.allclose(M, M.T)
            continue
        if not file_name.endswith(".py"):
            continue
        source = file.read_text(encoding="utf-8")
        ast.parse(source)
        owner = next(b for b in available_backends().values()
                     if file_name.endswith(b.config().suffix))
        if not all(importlib.util.find_spec(r) for r in owner.requires):  # an optional extra
            continue
        module = load_module(file, f"corpus_{file_name[:-3]}")
        assert module.JOINT_NAMES == model.joint_names  # the names, unchanged
        assert module.NQ == n
        if file_name.endswith("_numpy.py"):
            M = module.mass_matrix(np.linspace(-1, 1, n))
            assert M.shape == (n, n) and np.all(np.isfinite(M))
            assert np.allclose(M, M.T)
    assert "pwned" not in capfd.readouterr().out
