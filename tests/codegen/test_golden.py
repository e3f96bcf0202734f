"""generated/ holds committed output for the example robots; it must equal what the code
generates now, byte for byte.

After an intended change of the generated code, rewrite it with::

    python3 -m pytest tests/codegen/test_golden.py --update-golden
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

import eomgen
from eomgen.codegen.generate import select_backends
from support import ROOT, TESTS, erd_robots_dir, render_text_files

GOLDEN = ROOT / "generated"


def _examples() -> dict[str, Path | None]:
    robots = erd_robots_dir()
    return {
        "planar_2link": eomgen.example_path("planar_2link"),
        "puma560": eomgen.example_path("puma560_dh"),
        "ur5": robots / "ur_description/urdf/ur5_robot.urdf" if robots else None,
    }


def _render(path: Path) -> dict[str, str | bytes]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # PUMA 560's published inertias warn by design
        model = eomgen.load(path)
    files = render_text_files(model, select_backends("all"))  # .so files are not golden
    return {f.name: f.content for f in files if f.golden}


@pytest.mark.parametrize("name", list(_examples()))
@pytest.mark.slow
def test_generated_is_up_to_date(name, request):
    source = _examples()[name]
    if source is None:
        pytest.skip("example-robot-data is not installed")
    folder = GOLDEN / name
    files = _render(source)
    if request.config.getoption("--update-golden"):
        folder.mkdir(parents=True, exist_ok=True)
        for old in folder.iterdir():
            if old.name not in files:
                old.unlink()
        for file_name, content in files.items():
            (folder / file_name).write_text(content, encoding="utf-8", newline="\n")
        return
    assert folder.is_dir(), (f"{folder} missing: run pytest tests/codegen/test_golden.py "
                             "--update-golden")
    committed = sorted(p.name for p in folder.iterdir())
    assert committed == sorted(files), "generated/ holds other files than the generator makes"
    for file_name, content in files.items():
        on_disk = (folder / file_name).read_text(encoding="utf-8")
        assert on_disk == content, (f"generated/{name}/{file_name} is stale: "
                                    "run pytest tests/codegen/test_golden.py --update-golden")


@pytest.mark.slow
def test_generation_is_deterministic_across_processes():
    """Same input, byte-identical files, even with another hash seed: a fresh process, its
    hash seed other than this one's, writes the committed golden files of the PUMA 560, which
    test_generated_is_up_to_date renders again in this process (the hash seed random unless
    the caller fixed it)."""
    seed = "1" if os.environ.get("PYTHONHASHSEED") != "1" else "2"
    script = (
        "import sys, hashlib, warnings, eomgen\n"
        f"sys.path.insert(0, {str(TESTS)!r})\n"
        "from support import render_text_files\n"
        "from eomgen.codegen.generate import select_backends\n"
        "warnings.simplefilter('ignore')\n"
        "files = render_text_files(eomgen.load(eomgen.example_path('puma560_dh')), "
        "select_backends('all'))\n"
        "for f in sorted((f for f in files if f.golden), key=lambda f: f.name):\n"
        "    print(f.name, hashlib.sha256(f.content.encode()).hexdigest())\n")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         env=dict(os.environ, PYTHONHASHSEED=seed), check=True)
    committed = [f"{p.name} {hashlib.sha256(p.read_bytes()).hexdigest()}"
                 for p in sorted((GOLDEN / "puma560").iterdir(), key=lambda p: p.name)]
    assert out.stdout.splitlines() == committed
