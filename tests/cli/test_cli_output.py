"""What a new user trips over (issue 11): where the output goes, what a run says while it
works, and the options every command shares.

* Output on another file system (a mount point such as a container volume) is written, all
  files or none, with the previous output left as it was on failure.
* An output that cannot be written (a file given as the folder, a parent that is a file,
  ``/proc``) is one error line naming the path, exit code 2, found before any work and with
  nothing written, for every command that writes.
* Progress on stderr: stage lines with elapsed times in a log, an updating line on a terminal,
  nothing with ``--quiet``.
* ``--scene`` on every command that takes a description; scene runs of ``generate`` answered
  from the derivation cache; ``verify --samples 0`` refused; plain ``eomgen`` prints the help.

The commands run in real processes (``python -m eomgen.cli``), as a user runs them.
"""

from __future__ import annotations

import importlib.util
import io
import os
import pty
import re
import select
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from eomgen.common.output import GeneratedFile, OutputError, check_output_folder, write_atomically
from eomgen.common.progress import Progress, plural

from support import ERROR, ROOT, SCENES, erd_robots_dir, run_in_process, run_process

STAGE = re.compile(r"^eomgen: .* \[\+\d+\.\d s\]$")


def snapshot(folder: Path) -> dict[str, bytes | None]:
    """Every entry under ``folder`` (hidden ones included), files with their bytes."""
    return {str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else None)
            for p in sorted(folder.rglob("*"))}


def panda() -> Path:
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed (pip install -e '.[test]')")
    return robots / "panda_description" / "urdf" / "panda.urdf"


def has_analysis() -> bool:
    return all(importlib.util.find_spec(m) is not None
               for m in ("matplotlib", "mpmath", "scipy"))


# ----------------------------------------------------------------------------------------------
# 1. Output on another file system
# ----------------------------------------------------------------------------------------------


@pytest.fixture
def mount_point():
    """A fresh tmpfs mounted on an empty folder: a file system other than its parent's."""
    if not hasattr(os, "geteuid") or os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("mounting a tmpfs needs root and mount(8)")
    folder = Path(tempfile.mkdtemp(prefix="eomgen-mount-"))
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=16m", "tmpfs", str(folder)],
                          capture_output=True, text=True)
    if done.returncode != 0:
        folder.rmdir()
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.strip()}")
    try:
        assert os.stat(folder).st_dev != os.stat(folder.parent).st_dev
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=True)
        folder.rmdir()


def test_generate_into_a_mount_point(mount_point):
    """``-o`` on a mount point: the files are written (on main: EXDEV, Invalid cross-device
    link), files of other names are kept and no staging folder is left."""
    (mount_point / "notes.txt").write_text("mine\n")
    (mount_point / "planar_2link_numpy.py").write_text("# previous\n")
    done = run_process("generate", "--backend", "numpy", "--no-cache", "--quiet",
                       "-o", mount_point)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [str(mount_point / "planar_2link_numpy.py")]
    assert sorted(p.name for p in mount_point.iterdir()) == ["notes.txt",
                                                             "planar_2link_numpy.py"]
    assert (mount_point / "notes.txt").read_text() == "mine\n"
    assert (mount_point / "planar_2link_numpy.py").read_text().startswith("# Generated")
    fresh = mount_point / "new" / "out"  # a new folder inside the mount
    done = run_process("generate", "--backend", "numpy", "--no-cache", "--quiet", "-o", fresh)
    assert done.returncode == 0, done.stderr
    assert [p.name for p in fresh.iterdir()] == ["planar_2link_numpy.py"]


def test_a_failed_write_into_a_mount_point_leaves_the_previous_output(mount_point):
    (mount_point / "a.py").write_text("old a\n")
    before = snapshot(mount_point)
    files = [GeneratedFile("a.py", "new a\n"), GeneratedFile("b.py", "new b\n"),
             GeneratedFile("c.py", None)]  # neither text nor bytes: fails while staging
    with pytest.raises(TypeError):
        write_atomically(files, mount_point)
    assert snapshot(mount_point) == before
    assert write_atomically(files[:2], mount_point) == [mount_point / "a.py",
                                                       mount_point / "b.py"]
    assert snapshot(mount_point) == {"a.py": b"new a\n", "b.py": b"new b\n"}


def test_a_new_output_folder_appears_whole_or_not_at_all(tmp_path):
    """A missing output folder is staged beside it and renamed: on failure neither it nor the
    parents made for it remain; on success it has the usual permissions (not mkdtemp's 0700)."""
    outdir = tmp_path / "deep" / "er" / "out"
    with pytest.raises(TypeError):
        write_atomically([GeneratedFile("a.py", "a\n"), GeneratedFile("b.py", None)], outdir)
    assert list(tmp_path.iterdir()) == []
    write_atomically([GeneratedFile("a.py", "a\n")], outdir)
    assert (outdir / "a.py").read_text() == "a\n"
    umask = os.umask(0)
    os.umask(umask)
    assert outdir.stat().st_mode & 0o777 == 0o777 & ~umask
    assert sorted(p.name for p in outdir.parent.iterdir()) == ["out"]


# ----------------------------------------------------------------------------------------------
# 2. Output problems: one line, before the work, nothing written
# ----------------------------------------------------------------------------------------------

COMMANDS = ["generate", "notebook", "teach", "bench", "simulate"]


def _bad_outputs(tmp_path: Path, command: str) -> list[tuple[Path, str]]:
    a_file = tmp_path / "taken.txt"
    a_file.write_text("not a folder\n")
    cases = [(a_file / "out", "taken.txt is a file, not a folder"),
             (Path("/proc/eomgen_out"), "/proc does not accept new files")]
    if command == "notebook":
        cases.append((tmp_path, "it is a folder, not a file"))
    else:
        cases.append((a_file, "it is a file, not a folder"))
    return cases


@pytest.mark.parametrize("command", COMMANDS)
def test_an_output_that_cannot_be_written_is_one_line_before_the_work(command, tmp_path):
    if command in ("bench", "simulate") and not has_analysis():
        pytest.skip("bench and simulate need the analysis extra: pip install -e '.[analysis]'")
    if not Path("/proc/self").exists():
        pytest.skip("no /proc on this system")
    extra = {"teach": ["--format", "html"], "bench": ["--samples", "2", "--repeats", "1"],
             "simulate": ["--duration", "0.1", "--integrators", "rk4"]}.get(command, [])
    for output, problem in _bad_outputs(tmp_path, command):
        before = snapshot(tmp_path)
        done = run_in_process(command, *extra, "-o", output)
        assert done.returncode == 2, (command, output, done.stderr)
        lines = done.stderr.splitlines()
        assert len(lines) == 1, done.stderr
        assert lines[0].startswith(f"{ERROR}{output}: cannot write the output: "), lines
        assert problem in lines[0]
        assert done.stdout == ""
        assert snapshot(tmp_path) == before  # nothing written, no probe left


def test_check_output_folder_tells_a_writable_place_from_others(tmp_path):
    check_output_folder(tmp_path / "new" / "deeper")  # made later, with its parents
    check_output_folder(tmp_path)
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "f").write_text("")
    with pytest.raises(OutputError, match="is a file, not a folder"):
        check_output_folder(tmp_path / "f" / "g" / "h")


# ----------------------------------------------------------------------------------------------
# 3. Progress
# ----------------------------------------------------------------------------------------------


def test_generate_reports_each_stage_with_its_time_in_a_log(tmp_path):
    done = run_process("generate", "--no-cache", "--backend", "numpy,c", "-o", tmp_path / "o")
    assert done.returncode == 0, done.stderr
    *lines, hint = done.stderr.splitlines()
    assert lines and all(STAGE.match(line) for line in lines), lines
    assert hint.startswith("eomgen: to import, ")  # after the stages, no time: not a stage
    stages = [line.split(" [+")[0].removeprefix("eomgen: ") for line in lines]
    assert stages[0].startswith("deriving M, C, g, tau of planar_2link (2 joints)")
    assert stages[1].startswith("derived in ")
    assert stages[2] == "numpy: generating"
    assert stages[3].startswith("numpy: planar_2link_numpy.py (")
    assert stages[4] == "c: generating"  # before the compilation, which takes the time
    times = [float(line.rsplit("[+", 1)[1].removesuffix(" s]")) for line in lines]
    assert times == sorted(times)


def test_quiet_silences_every_command(tmp_path, monkeypatch):
    """``--quiet`` on every command (bench: in the scene test below); without it, stage
    lines. In process: what is printed is the commands' doing, not the interpreter's."""
    monkeypatch.chdir(tmp_path)
    runs = [("verify", "--samples", "2"), ("generate", "--backend", "numpy", "--no-cache"),
            ("notebook", "-o", tmp_path / "n.ipynb"), ("teach", "--format", "md", "--no-check")]
    if has_analysis():
        runs.append(("simulate", "--duration", "0.05", "--integrators", "rk4", "--dt", "1e-2"))
    for args in runs:
        out = ["-o", tmp_path / args[0]] if args[0] in ("generate", "teach", "simulate") else []
        done = run_in_process(*args, *out, "--quiet")
        assert done.returncode == 0, (args, done.stderr)
        assert done.stderr == "", args
    for args in runs[2:4]:  # the others' stage lines are tested on their own
        loud = run_in_process(*args, *(["-o", tmp_path / "t"] if args[0] == "teach" else []))
        assert loud.returncode == 0 and loud.stderr.splitlines(), args
        assert all(STAGE.match(line) for line in loud.stderr.splitlines()), loud.stderr


@pytest.mark.skipif(not has_analysis(), reason="simulate needs the analysis extra")
@pytest.mark.slow
def test_simulate_names_each_integrator_in_a_log(tmp_path):
    done = run_process("simulate", "--duration", "0.05", "--integrators", "euler,rk4",
                       "--dt", "1e-2", "--rtol", "1e-4", "-o", tmp_path)
    assert done.returncode == 0, done.stderr
    stages = [line.split(" [+")[0] for line in done.stderr.splitlines()]
    assert stages == ["eomgen: deriving M, C, g and tau of planar_2link (2 joints)",
                      "eomgen: integrating: 0/3",
                      "eomgen: integrating: 1/3, reference (DOP853, rtol = atol = 1e-12)",
                      "eomgen: integrating: 2/3, explicit Euler, dt = 0.01 s",
                      "eomgen: integrating: 3/3, RK4, dt = 0.01 s",
                      "eomgen: writing the report and plot"], stages


def test_a_terminal_gets_one_updating_line(tmp_path):
    """stderr a terminal (a pseudo-terminal here): the stages overwrite each other
    (carriage return, erase line) and carry no elapsed times."""
    master, slave = pty.openpty()
    try:
        process = subprocess.Popen(
            [sys.executable, "-m", "eomgen.cli", "generate", "--no-cache", "--backend", "numpy",
             "-o", str(tmp_path / "o")], stdout=subprocess.PIPE, stderr=slave)
        os.close(slave)
        slave = None
        seen = b""
        while True:
            ready, _, _ = select.select([master], [], [], 120)
            if not ready:
                break
            try:
                chunk = os.read(master, 4096)
            except OSError:  # the child closed the terminal
                break
            if not chunk:
                break
            seen += chunk
        stdout, _ = process.communicate(timeout=120)
    finally:
        os.close(master)
        if slave is not None:
            os.close(slave)
    assert process.returncode == 0
    text = seen.decode()
    assert "\r\x1b[Keomgen: deriving M, C, g, tau of planar_2link" in text
    assert "\r\x1b[Keomgen: numpy: planar_2link_numpy.py" in text
    progress, hint = text.rsplit("\r\x1b[K", 1)  # cleared before the results
    assert "[+" not in progress and "\n" not in progress.replace("\r\n", "")
    assert hint.startswith("eomgen: to import, ") and hint.endswith("\r\n")  # one line left
    assert stdout.decode().splitlines() == [str(tmp_path / "o" / "planar_2link_numpy.py")]


def test_steps_in_a_log_print_each_tenth_and_each_named_step():
    stream = io.StringIO()
    progress = Progress(stream=stream, tty=False, clock=lambda: 0.0)
    with progress.steps(20, "measuring") as steps:
        for _ in range(20):
            steps.update(1)
    assert stream.getvalue().splitlines() == [f"eomgen: measuring: {k}/20 [+0.0 s]"
                                              for k in range(0, 21, 2)]
    quiet = io.StringIO()
    with Progress(quiet=True, stream=quiet, tty=False).steps(3, "x") as steps:
        steps.update(1, "named")
    assert quiet.getvalue() == ""


def test_a_warning_or_error_after_a_terminal_line_starts_a_new_line():
    from eomgen.common.progress import end_line

    stream = io.StringIO()
    progress = Progress(stream=stream, tty=True)
    progress("deriving")
    progress("compiling")
    end_line()  # what the CLI calls before a warning or an error
    end_line()  # once only
    assert stream.getvalue() == "\r\x1b[Keomgen: deriving\r\x1b[Keomgen: compiling\n"
    progress.clear()
    assert stream.getvalue().endswith("compiling\n")  # nothing left to clear


class _Clock:
    """A clock the test moves (seconds)."""

    def __init__(self):
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def _wait_for(condition, seconds: float = 10.0) -> None:
    import time

    deadline = time.monotonic() + seconds
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.01)


def test_a_long_stage_is_repeated_with_its_time_until_the_next():
    """Issue 40: no stretch of a command is silent for longer than the heartbeat (10 s in the
    CLI): a stage that runs on is repeated with the time spent in it; a new stage, ``clear``
    (the results) and ``quiet`` end the repeats."""
    stream, clock = io.StringIO(), _Clock()
    progress = Progress(stream=stream, tty=False, clock=clock, heartbeat=10.0)
    progress("deriving M of a long chain")
    clock.now = 9.0
    import time
    time.sleep(0.5)  # the thread looks several times: under 10 s, nothing yet
    assert stream.getvalue().count("\n") == 1
    clock.now = 25.0
    _wait_for(lambda: stream.getvalue().count("\n") >= 2)
    clock.now = 26.0
    progress("compiling")
    progress.clear()
    clock.now = 100.0
    time.sleep(0.5)  # the thread would have had its chance
    assert stream.getvalue().splitlines() == [
        "eomgen: deriving M of a long chain [+0.0 s]",
        "eomgen: deriving M of a long chain (still working, 25 s) [+25.0 s]",
        "eomgen: compiling [+26.0 s]"]
    quiet = io.StringIO()
    silent = Progress(quiet=True, stream=quiet, tty=False, clock=clock, heartbeat=0.01)
    silent("deriving")
    time.sleep(0.1)
    assert quiet.getvalue() == ""


def test_the_cli_stops_the_heartbeat_when_the_command_ends(monkeypatch, tmp_path):
    """Through the CLI with a heartbeat of 0.05 s: repeated stage lines while it works, and
    none once the command has returned (the thread would write into whatever stderr is
    then)."""
    import threading
    import time

    from eomgen.common import progress as progress_module

    monkeypatch.setattr(progress_module, "HEARTBEAT_SECONDS", 0.05)
    from eomgen.cli import generate_verify

    monkeypatch.setattr(generate_verify, "HEARTBEAT_SECONDS", 0.05)
    done = run_in_process("verify", "elbow_rrr", "--samples", "3")
    assert done.returncode == 0, done.stderr
    assert "(still working, " in done.stderr, done.stderr
    time.sleep(0.2)
    assert not [t for t in threading.enumerate() if t.name == "eomgen-progress"]


def test_plural():
    assert [plural(n, "joint") for n in (0, 1, 2)] == ["0 joints", "1 joint", "2 joints"]


def test_one_joint_is_not_joints(tmp_path):
    path = tmp_path / "pendulum.yaml"
    path.write_text("""\
name: pendulum
links:
  - {name: base}
  - {name: rod, mass: 1, com: [0, 0, -1], inertia: {ixx: 0.1, iyy: 0.1, izz: 0.1}}
joints:
  - {name: swing, type: revolute, parent: base, child: rod, axis: [0, 1, 0]}
""")
    done = run_process("verify", path, "--samples", "2")
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("derived pendulum (1 joint: swing) in ")
    assert "(1 joint)" in done.stderr and "joints" not in done.stderr


# ----------------------------------------------------------------------------------------------
# 4. Scenes everywhere, the cache for scenes, refused options, plain eomgen
# ----------------------------------------------------------------------------------------------


def test_verify_and_notebook_take_a_scene(tmp_path):
    """The Panda reduced to its shoulder and elbow: verify checks the reduced model against
    Newton-Euler; the notebook's first cells (the description and the scene written in) load
    the same reduced model."""
    urdf, scene = panda(), SCENES / "panda_two_joints.yaml"
    done = run_in_process("verify", urdf, "--scene", scene, "--samples", "3", "--quiet")
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("derived panda (2 joints: panda_joint2, panda_joint4) in ")
    assert done.stdout.splitlines()[-1] == "all checks passed"
    notebook = tmp_path / "panda.ipynb"
    done = run_in_process("notebook", urdf, "--scene", scene, "-o", notebook, "--quiet")
    assert done.returncode == 0, done.stderr
    import nbformat

    import eomgen
    from eomgen.reduction import apply_scene
    from eomgen.scene import load_scene

    namespace: dict = {}
    for cell in nbformat.read(notebook, as_version=4).cells:  # the notebook's own cells, up
        if cell.cell_type == "code" and "model" not in namespace:  # to the one making model
            exec(cell.source, namespace)
    expected = apply_scene(eomgen.load(urdf), load_scene(scene)).model
    assert namespace["model"].joint_names == expected.joint_names == ("panda_joint2",
                                                                       "panda_joint4")
    from eomgen.cache import model_fingerprint  # every field but the source path

    assert model_fingerprint(namespace["model"]) == model_fingerprint(expected)


@pytest.mark.slow
@pytest.mark.skipif(not has_analysis(), reason="bench and simulate need the analysis extra")
def test_bench_and_simulate_take_a_scene(tmp_path):
    urdf, scene = panda(), SCENES / "panda_two_joints.yaml"
    done = run_in_process("simulate", urdf, "--scene", scene, "--duration", "0.05",
                          "--integrators", "rk4", "--dt", "1e-2", "--q0", "0.3,-1", "-o", tmp_path,
                          "--quiet")
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("panda (2 joints)")
    done = run_in_process("bench", urdf, "--scene", scene, "--samples", "2", "--repeats", "1",
                          "--batch-size", "2", "-o", tmp_path, "--quiet")
    assert done.returncode == 0, done.stderr
    assert "eomgen: warning" not in done.stderr or all(
        line.startswith("eomgen: warning: ") for line in done.stderr.splitlines())  # quiet
    assert "# Speed against error: panda (2 joints)" in done.stdout


def test_scene_runs_of_generate_are_cached(tmp_path):
    urdf = panda()
    scene = tmp_path / "two.yaml"
    shutil.copy(SCENES / "panda_two_joints.yaml", scene)
    cache = tmp_path / "cache"
    common = ["--scene", scene, "--backend", "numpy", "--cache-dir", cache]
    first = run_process("generate", urdf, *common, "-o", tmp_path / "a")
    assert first.returncode == 0, first.stderr
    assert "using cached" not in first.stderr
    second = run_process("generate", urdf, *common, "-o", tmp_path / "b")
    assert second.returncode == 0, second.stderr
    assert [line for line in second.stderr.splitlines() if "cached" in line] == [
        line for line in second.stderr.splitlines() if line.startswith("eomgen: using cached")]
    assert any(line.startswith("eomgen: using cached") for line in second.stderr.splitlines())
    assert "deriving" not in second.stderr
    assert snapshot(tmp_path / "a") == snapshot(tmp_path / "b")
    assert sorted(snapshot(tmp_path / "b")) == ["panda_numpy.py", "panda_scene_report.md"]
    scene.write_text(scene.read_text().replace("panda_joint5: 0", "panda_joint5: 0.5"))
    changed = run_process("generate", urdf, *common, "-o", tmp_path / "c")
    assert changed.returncode == 0, changed.stderr
    assert "using cached" not in changed.stderr and "deriving" in changed.stderr
    assert (tmp_path / "c" / "panda_numpy.py").read_bytes() != \
        (tmp_path / "a" / "panda_numpy.py").read_bytes()


def test_verify_refuses_zero_samples():
    done = run_process("verify", "--samples", "0")
    assert done.returncode == 2
    assert done.stderr.splitlines() == [f"{ERROR}--samples must be at least 1, got 0"]


def test_plain_eomgen_prints_the_help_and_succeeds():
    done = run_process()
    assert done.returncode == 0, done.stderr
    assert "Commands:" in done.stdout and "generate" in done.stdout
    assert done.stderr == ""


def test_gitignore_covers_the_default_outputs():
    """Every default output folder of the CLI (read from its options) is ignored by git."""
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    from eomgen.cli import main

    defaults = {p.default for command in main.commands.values() for p in command.params
                if p.name == "outdir"}
    assert defaults >= {"eomgen_output", "eomgen_handout", "eomgen_bench", "eomgen_simulate"}
    paths = [f"{d}/x.py" for d in sorted(defaults)] + ["planar_2link_derivation.ipynb"]
    done = subprocess.run(["git", "check-ignore", "--no-index", *paths], cwd=ROOT,
                          capture_output=True, text=True)
    assert sorted(done.stdout.split()) == sorted(paths)
    kept = subprocess.run(["git", "check-ignore", "--no-index", "examples/x.ipynb"], cwd=ROOT,
                          capture_output=True, text=True)
    assert kept.stdout == ""


# ----------------------------------------------------------------------------------------------
# 5. teach without pdflatex
# ----------------------------------------------------------------------------------------------


def _without_pdflatex(tmp_path: Path) -> dict[str, str]:
    empty = tmp_path / "bin"
    empty.mkdir()
    return dict(os.environ, PATH=str(empty))


def test_teach_defaults_to_html_without_pdflatex(tmp_path):
    env = _without_pdflatex(tmp_path)
    done = run_process("teach", "--no-check", "-o", tmp_path / "h", env=env)
    assert done.returncode == 0, done.stderr
    assert done.stderr.splitlines()[0] == (
        "eomgen: pdflatex not found: writing the html handout instead of the pdf (install TeX "
        "Live for pdf, or choose with --format)")
    assert done.stdout.splitlines() == [str(tmp_path / "h" / "planar_2link_handout.html")]


def test_teach_pdf_without_pdflatex_is_refused_before_the_work(tmp_path):
    env = _without_pdflatex(tmp_path)
    before = snapshot(tmp_path)
    done = run_process("teach", "--format", "pdf,html", "-o", tmp_path / "h", env=env)
    assert done.returncode == 2
    assert done.stderr.splitlines() == [
        f"{ERROR}--format pdf needs pdflatex, which is not installed (TeX Live: apt install "
        "texlive-latex-base); choose html, md or tex"]
    assert snapshot(tmp_path) == before


def test_the_readme_finds_the_example_robots():
    """The README's one-liner for example-robot-data's ``robots/`` folder finds it, and the
    robots it names are there."""
    if erd_robots_dir() is None:
        pytest.skip("example-robot-data is not installed")
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    line = next(line.strip() for line in readme.splitlines() if "ROBOTS=$(python3 -c" in line)
    code = line.split('python3 -c "', 1)[1].rsplit('")', 1)[0]
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    robots = Path(done.stdout.strip())
    assert robots.resolve() == erd_robots_dir().resolve()
    named = re.findall(r"`\$ROBOTS/([^`]+\.urdf)`", readme)
    assert len(named) >= 3 and all((robots / path).is_file() for path in named), named


def test_name_chooses_the_modules_stem_says_how_to_import_and_keys_the_cache(tmp_path):
    """Issue 29: modules were named after the robot (uf_robot_* for xarm7.urdf) with no option
    and no hint. --name STEM names them, one stderr line says how to import them (none under
    --quiet), a bad STEM is one error line and nothing written, and the derivation cache keeps
    names apart (the command's cache and the library's)."""
    cache = tmp_path / "cache"
    common = ("--backend", "numpy,latex", "--cache-dir", cache)
    named = run_in_process("generate", "--name", "arm2", "-o", tmp_path / "a", *common)
    assert named.returncode == 0, named.stderr
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == ["arm2.tex", "arm2_numpy.py"]
    hints = [line for line in named.stderr.splitlines() if "import" in line]
    assert hints == [f"eomgen: to import, put the folder on the path, sys.path.insert(0, "
                     f"{str(tmp_path / 'a')!r}), then import arm2_numpy"]
    sys.path.insert(0, str(tmp_path / "a"))
    try:
        module = importlib.import_module("arm2_numpy")
        assert module.NQ == 2
    finally:
        sys.path.remove(str(tmp_path / "a"))
        sys.modules.pop("arm2_numpy", None)

    plain = run_in_process("generate", "-o", tmp_path / "b", *common)  # not the cached arm2
    assert plain.returncode == 0 and "using cached result" not in plain.stderr
    assert (tmp_path / "b" / "planar_2link_numpy.py").is_file()
    assert "--name STEM names them STEM_*" in plain.stderr.splitlines()[-1]
    again = run_in_process("generate", "--name", "arm2", "-o", tmp_path / "c", *common,
                           "--quiet")
    assert again.returncode == 0 and again.stderr == ""  # the cache answers, silently
    assert (tmp_path / "c" / "arm2_numpy.py").read_bytes() == \
        (tmp_path / "a" / "arm2_numpy.py").read_bytes()

    for bad in ("2arm", "arm-2", "class", "bras_à"):
        refused = run_in_process("generate", "--name", bad, "-o", tmp_path / "d", *common)
        assert refused.returncode == 2 and not (tmp_path / "d").exists()
        assert refused.stderr == (f"{ERROR}--name: {bad!r} cannot name a Python module "
                                  "(letters, digits and underscores, not starting with a "
                                  "digit, not a keyword)\n")

    import eomgen
    from eomgen.codegen.generate import generate

    model = eomgen.load(eomgen.example_path("planar_2link"))
    library = tmp_path / "lib"
    first = generate(model, library / "x", "numpy", stem="arm3", cache_dir=cache)
    second = generate(model, library / "y", "numpy", cache_dir=cache)
    assert [p.name for p in first] == ["arm3_numpy.py"]
    assert [p.name for p in second] == ["planar_2link_numpy.py"]
