"""Every code block of README.md and docs/*.md is run, or shown and said to be so (the rule:
tests/README.md, tests/support/doc_blocks.py): ``python`` blocks in process, a file's blocks in
order in one namespace; ``console`` blocks command by command in a subprocess, in a temporary
folder holding the example robots (``$ROBOTS``, the URDFs by name, ``eomgen/robots``,
``examples/``). A block that stopped being true (a function renamed, an option gone, a
sentence like "not done yet" beside a working feature shown in a block) fails here."""

from __future__ import annotations

import importlib.util
import os
import re
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest
import yaml

from support import ROOT, run_in_process
from support.doc_blocks import CONSOLE, PYTHON, RUN, SHOWN, blocks, indented_code, markdown_files

#: The example-robot-data URDFs the docs name by file name, as found under ``$ROBOTS``.
URDFS = {
    "ur5_robot.urdf": "ur_description/urdf/ur5_robot.urdf",
    "panda.urdf": "panda_description/urdf/panda.urdf",
    "talos_reduced.urdf": "talos_data/robots/talos_reduced.urdf",
    "solo12.urdf": "solo_description/robots/solo12.urdf",
}
#: The folders of the repository the docs' commands name by relative path.
FOLDERS = ("eomgen", "examples")

#: What makes a command need a shell: pipes, redirections, lists, substitutions, globs.
SHELL = re.compile(r"[|<>;&`*?]|\$\(")

FILES = markdown_files()
ALL = [block for path in FILES for block in blocks(path)]


def run_command(command: str, workspace: Path) -> subprocess.CompletedProcess:
    """A console block's command: a plain ``eomgen ARGS`` (no pipe, redirection, command
    substitution or second command) in this process, its ``$VARIABLES`` expanded as the shell
    would (the process start-up is tested in tests/cli; each start costs about a second of
    imports); anything else in ``bash`` in a subprocess."""
    words = shlex.split(command.replace("\\\n", " "), comments=True)
    if words[0] == "eomgen" and not SHELL.search(command.split("#")[0]):
        return run_in_process(*(os.path.expandvars(w) for w in words[1:]))
    return subprocess.run(["bash", "-c", command], cwd=workspace, capture_output=True,
                          text=True, timeout=600)


def _runnable(path: Path) -> bool:
    return any(b.language in RUN and b.not_run is None for b in blocks(path))


@pytest.fixture
def workspace(tmp_path, erd_robots_dir, monkeypatch):
    """A folder like a user's: the example robots at hand, ``eomgen`` (and ``python``) on the
    PATH running this checkout with this interpreter; every output is written here."""
    work = tmp_path / "work"
    work.mkdir()
    for name in FOLDERS:
        (work / name).symlink_to(ROOT / name, target_is_directory=True)
    for name, below in URDFS.items():
        (work / name).symlink_to(erd_robots_dir / below)
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for name, run in (("eomgen", "-m eomgen.cli"), ("python", ""), ("python3", "")):
        (bin_dir / name).write_text(f'#!/bin/sh\nexec "{sys.executable}" {run} "$@"\n')
        (bin_dir / name).chmod(0o755)
    monkeypatch.setenv("PATH", f"{bin_dir}{os.pathsep}{os.environ['PATH']}")
    monkeypatch.setenv("ROBOTS", str(erd_robots_dir))
    monkeypatch.setenv("PYTHONPATH", str(ROOT))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.chdir(work)
    monkeypatch.syspath_prepend(str(work))
    temporary = str(Path(tempfile.gettempdir()).resolve())
    kept = tuple(str(Path(p).resolve()) for p in (ROOT, sys.prefix, sys.base_prefix))
    for name, module in list(sys.modules.items()):  # a generated module another test imported
        file = str(getattr(module, "__file__", "") or "")
        if "." not in name and file.startswith(temporary) and not file.startswith(kept):
            del sys.modules[name]  # would shadow the one a block generates under its name
    before = set(sys.modules)
    yield work
    for name in set(sys.modules) - before:  # the generated modules the blocks imported
        if str(getattr(sys.modules[name], "__file__", "") or "").startswith(str(work)):
            del sys.modules[name]


def run_blocks(path: Path, workspace: Path) -> list[str]:
    """Run the blocks of ``path`` in order (python in one namespace, console commands one by
    one); an AssertionError names the block that failed. Returns the blocks left out because
    the optional modules they need are missing."""
    namespace = {"__name__": "__doc__"}
    missing = []
    for block in blocks(path):
        if block.not_run is not None:
            continue
        absent = [m for m in block.needs if importlib.util.find_spec(m) is None]
        if absent:
            missing.append(f"{block.where} (needs {', '.join(absent)})")
            continue
        if block.language == PYTHON:
            code = compile(block.text, block.where, "exec")
            try:
                exec(code, namespace)  # noqa: S102 - the documentation's own example
            except Exception as error:
                raise AssertionError(f"{block.where}: {type(error).__name__}: {error}") from error
        elif block.language == CONSOLE:
            commands = block.commands()
            assert commands, f"{block.where}: a console block without a '$ ' command"
            for command in commands:
                if block.run_with and command.startswith("eomgen "):
                    command = f"{command.split('#')[0].rstrip()} {block.run_with}"
                done = run_command(command, workspace)
                assert done.returncode == 0, (
                    f"{block.where}: `{command}` exited with {done.returncode}\n{done.stderr}")
    return missing


#: Pages whose blocks take more than about 5 s together (each block is small; a page runs its
#: blocks in one test because they share a namespace): 12–32 s each in a run of tests/docs on
#: 2 busy cores. The other pages, the README among them, stay in the quick subset.
SLOW_PAGES = {"docs/cli.md", "docs/backends.md", "docs/contact.md", "docs/actuators.md",
              "docs/regressor.md"}


@pytest.mark.parametrize("path", [
    pytest.param(p, marks=[pytest.mark.slow] if str(p.relative_to(ROOT)) in SLOW_PAGES else [],
                 id=str(p.relative_to(ROOT)))
    for p in FILES if _runnable(p)])
def test_the_code_blocks_run(path, workspace):
    missing = run_blocks(path, workspace)
    if missing:
        pytest.skip(f"the other blocks ran; not these, whose extras are not installed: "
                    f"{'; '.join(missing)}")


STALE = {
    "an option that is gone": "```console\n$ eomgen generate --backend numpy --no-such-option\n```\n",
    "a renamed function": "```python\nimport eomgen\neomgen.derive_dynamics\n```\n",
    "a changed value": "```python\nimport eomgen\n"
                       "assert eomgen.load(eomgen.example_path('planar_2link')).dof == 3\n```\n",
    "a robot not at hand": "```console\n$ eomgen verify no_such_robot.urdf\n```\n",
}


@pytest.mark.parametrize("text", STALE.values(), ids=STALE.keys())
def test_a_stale_block_fails_and_says_where(text, workspace):
    page = workspace / "stale.md"
    page.write_text("# A page\n\nSome text.\n\n" + text, encoding="utf-8")
    with pytest.raises(AssertionError, match="stale.md:5"):
        run_blocks(page, workspace)
    marked = workspace / "marked.md"
    marked.write_text("<!-- not-run: shows a mistake -->\n" + text, encoding="utf-8")
    assert run_blocks(marked, workspace) == []


def test_the_readmes_symbolic_tour_runs_on_its_own():
    """The README's Python block after "The same from Python, symbolically:" needs nothing from
    the blocks before it (a reader copies it alone): run here in a namespace of its own."""
    readme = ROOT / "README.md"
    text = readme.read_text(encoding="utf-8")
    after = text[:text.index("The same from Python, symbolically:")].count("\n") + 1
    block = next(b for b in blocks(readme) if b.language == PYTHON and b.line > after)
    exec(compile(block.text, block.where, "exec"), {"__name__": "__doc__"})  # noqa: S102


def test_every_block_says_what_it_is():
    """Every fenced block names a language that is run or shown; the not-run marker stands
    only before a block that would otherwise run; no block is indented (an indented block
    names no language); YAML blocks parse."""
    unknown = [(b.where, b.language) for b in ALL if b.language not in RUN + SHOWN]
    assert unknown == [], "name the language of each block (tests/README.md)"
    misplaced = [b.where for b in ALL
                 if (b.not_run is not None or b.needs or b.run_with) and b.language not in RUN]
    assert misplaced == []
    indented = [f"{p.relative_to(ROOT)}:{line}" for p in FILES for line in indented_code(p)]
    assert indented == [], "fence these blocks and name their language"
    for block in ALL:
        if block.language == "yaml":
            yaml.safe_load(block.text)
    assert SLOW_PAGES <= {str(p.relative_to(ROOT)) for p in FILES if _runnable(p)}


def test_at_most_one_block_in_ten_is_not_run():
    code = [b for b in ALL if b.language in RUN]
    not_run = [b for b in code if b.not_run is not None]
    assert len(code) >= 20 and 10 * len(not_run) <= len(code), [b.where for b in not_run]


def test_the_set_up_commands_are_the_ones_ci_runs():
    """The README's two set-up commands (not run here: they install) are those of
    docs/getting-started.md, and the second is the test command .ci/run runs first, as written,
    in a fresh virtual environment, before it installs any other extra."""
    readme, started = (next(b for b in blocks(path) if b.not_run is not None)
                       for path in (ROOT / "README.md", ROOT / "docs" / "getting-started.md"))
    assert readme.commands() == started.commands()
    main_job, tests = readme.commands()
    assert main_job == "python3 -m pip install -e . && eomgen generate"
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    runs = [i for i, line in enumerate(ci) if line == tests or line.startswith(tests + " || ")]
    venv = next(i for i, line in enumerate(ci) if line.startswith("python3 -m venv "))
    installs = [i for i, line in enumerate(ci) if "pip install" in line and i not in runs]
    assert len(runs) == 1 and venv < runs[0] < min(installs), "stage 1 is the README's command"
    # the suite's size and time are stated once, in the README
    stated = [p.name for p in FILES
              if re.search(r"\d[\d,]* tests in", p.read_text(encoding="utf-8"))]
    assert stated == ["README.md"]
