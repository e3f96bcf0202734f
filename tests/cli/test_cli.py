"""The command line: ``eomgen verify``, help, version, and what bad input looks like.

Most runs go through click's CliRunner (in process, stdout and stderr kept apart); the few that
need a real process (the ``python -m`` entry point, ``--debug`` tracebacks) use subprocess.
"""

from __future__ import annotations

import subprocess

import pytest

import eomgen
import support
from eomgen.robots import example_path

from support import ERROR, WARNING, erd_robots_dir, run_cli as run, write



def run_process(*args: str) -> subprocess.CompletedProcess:
    return support.run_process(*args, timeout=120)


# ----------------------------------------------------------------------------------------------
# Success
# ----------------------------------------------------------------------------------------------


def test_verify_without_arguments_checks_the_bundled_arm():
    result = run("verify")
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert lines[0].startswith("derived planar_2link (2 joints: joint1, joint2)")
    assert lines[-1] == "all checks passed"
    assert "(exact)" in result.stdout
    assert "FAIL" not in result.stdout
    assert [line.split(" [+")[0] for line in result.stderr.splitlines()] == [
        "eomgen: deriving M, C, g and tau of planar_2link (2 joints)",
        "eomgen: checking at 20 random states"]  # progress on stderr; results on stdout
    quiet = run("verify", "--quiet")
    assert quiet.stdout.splitlines()[1:] == lines[1:] and quiet.stderr == ""


def test_verify_a_urdf_from_example_robot_data():
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    result = run("verify", robots / "ur_description/urdf/ur5_robot.urdf", "--samples", "5",
                 "--quiet")
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("derived ur5 (6 joints: shoulder_pan_joint, ")
    assert result.stdout.splitlines()[-1] == "all checks passed"
    assert result.stderr == ""


def test_entry_point_as_a_module():
    """``python -m eomgen.cli`` (what the ``eomgen`` script runs), in a real process."""
    done = run_process("verify", "--samples", "3", "--seed", "7")
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1] == "all checks passed"
    assert "3 samples" in done.stdout


def test_failed_check_exits_1(tmp_path):
    """A description that loads but whose mass matrix is singular (a massless link on a
    prismatic joint): the report says which check failed, exit code 1, no error line."""
    path = write(tmp_path / "slider.yaml", """\
name: slider
links:
  - {name: base}
  - {name: arm, mass: 2, com: [1, 0, 0], inertia: {ixx: 1, iyy: 1, izz: 1}}
  - {name: tip}
joints:
  - {name: turn, type: revolute, parent: base, child: arm, axis: [0, 0, 1]}
  - {name: slide, type: prismatic, parent: arm, child: tip, axis: [1, 0, 0]}
""")
    result = run("verify", path, "--samples", "3")
    assert result.exit_code == 1, result.output
    assert "  FAIL M positive definite" in result.stdout
    assert result.stdout.splitlines()[-1] == "SOME CHECKS FAILED"
    assert ERROR not in result.stderr


# ----------------------------------------------------------------------------------------------
# Bad input: exit code 2 and one line on stderr naming the file
# ----------------------------------------------------------------------------------------------

LINK = ('<link name="arm"><inertial><mass value="{mass}"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>')
JOINT = ('<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
         '<axis xyz="0 0 1"/></joint>')

BAD = {
    # id: (file name or None for a missing file, content, words the message must contain)
    "malformed URDF": ("bad.urdf", '<robot name="r">\n<link name="a">\n</robot>\n',
                       ["line 3", "malformed XML"]),
    "negative mass": ("negative.urdf",
                      f'<robot name="r"><link name="base"/>{LINK.format(mass=-2)}{JOINT}</robot>',
                      ["link 'arm'", "mass -2.0 is negative"]),
    "unknown suffix": ("robot.txt", "name: r\n", ["unknown file type '.txt'"]),
    "missing file": (None, "", ["no such file"]),
    "YAML unknown key": ("robot.yaml", "name: r\nlinks:\n  - {name: base, colour: red}\n"
                                       "joints: []\n", ["links[0] 'base'", "colour"]),
    "YAML neither format": ("robot.yaml", "name: r\n", ["cannot tell which format"]),
    "floating joint": ("float.urdf",
                       f'<robot name="r">{LINK.replace("arm", "base").format(mass=1)}'
                       f'{LINK.format(mass=1)}{JOINT.replace("revolute", "floating")}</robot>',
                       ["joint 'j'", "read as the robot's free flyer only from a massless root"]),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_input_is_one_error_line_naming_the_file(tmp_path, case):
    name, content, words = BAD[case]
    path = tmp_path / (name or "missing.urdf")
    if name is not None:
        write(path, content)
    result = run("verify", path)
    assert result.exit_code == 2, result.output
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(f"{ERROR}{path}: "), lines[0]
    for word in words:
        assert word in lines[0], lines[0]
    assert "Traceback" not in result.stderr


def test_a_file_name_with_a_line_break_stays_on_one_line(tmp_path):
    path = write(tmp_path / "two\nlines.urdf", "<robot")
    result = run("verify", path)
    assert result.exit_code == 2
    assert len(result.stderr.splitlines()) == 1, result.stderr
    assert result.stderr.startswith(ERROR) and "two\\nlines.urdf" in result.stderr


def test_debug_shows_a_traceback(tmp_path):
    path = write(tmp_path / "negative.urdf",
                 f'<robot name="r"><link name="base"/>{LINK.format(mass=-2)}{JOINT}</robot>')
    plain = run_process("verify", path)
    assert plain.returncode == 2 and plain.stderr.count("\n") == 1
    debug = run_process("verify", path, "--debug")
    assert debug.returncode != 0
    assert "Traceback (most recent call last)" in debug.stderr
    assert "eomgen.errors.InvalidInertiaError" in debug.stderr and "is negative" in debug.stderr
    assert ERROR not in debug.stderr


# ----------------------------------------------------------------------------------------------
# Warnings and --strict
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("command", ["verify", "generate", "teach", "bench"])
def test_a_near_miss_of_a_bundled_name_is_suggested(command, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # no file of that name here
    result = run(command, "elbow_rr", "--quiet")
    assert result.exit_code == 2, result.output
    assert result.stderr.splitlines() == [
        f"{ERROR}elbow_rr: no such file; did you mean 'elbow_rrr'?"]


def test_a_bundled_name_is_a_description_in_python_too():
    assert eomgen.load("elbow_rrr") == eomgen.load(example_path("elbow_rrr"))


def test_a_near_miss_of_a_file_is_suggested_with_its_folder(tmp_path):
    write(tmp_path / "arm.urdf", "<robot/>")
    result = run("verify", tmp_path / "arms.urdf", "--quiet")
    assert result.exit_code == 2, result.output
    assert result.stderr.splitlines() == [
        f"{ERROR}{tmp_path / 'arms.urdf'}: no such file; did you mean '{tmp_path / 'arm.urdf'}'?"]
    far = run("verify", tmp_path / "nothing_alike.yaml", "--quiet")
    assert far.stderr.splitlines() == [f"{ERROR}{tmp_path / 'nothing_alike.yaml'}: no such file"]


def test_a_misspelled_output_is_one_short_line(tmp_path):
    """The suggestions first, then where the list is: not the list of every output."""
    from eomgen.outputs import OUTPUTS

    result = run("generate", "--outputs", "M,regresor", "-o", tmp_path / "out", "--no-cache")
    assert result.exit_code == 2, result.output
    (line,) = result.stderr.splitlines()
    assert line == (f"{ERROR}--outputs: unknown output 'regresor'; did you mean 'regressor' or "
                    "'base_regressor'? (docs/outputs.md lists them all; in Python, "
                    "eomgen.outputs.OUTPUTS)")
    assert sum(name in line for name in OUTPUTS) <= 3 and len(line) < 200
    assert "`regressor`" in (support.ROOT / "docs/outputs.md").read_text(encoding="utf-8")
    assert not (tmp_path / "out").exists()


def test_puma560_passes_silently_even_under_strict():
    """Its published links 1 and 3 break the triangle inequality, but its dynamics are a
    physical robot's (tests/parsers/test_yaml_dh.py): nothing to warn about or refuse."""
    result = run("verify", example_path("puma560_dh"), "--samples", "3", "--quiet", "--strict")
    assert result.exit_code == 0, result.output
    assert result.stderr == ""
    assert result.stdout.splitlines()[-1] == "all checks passed"


#: A two-joint arm whose tip link has no <inertial>: joint 'wrist' moves no mass.
MASSLESS_TIP = """<robot name="arm">
  <link name="base"/>
  <link name="upper"><inertial><origin xyz="0.5 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="tip"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="wrist" type="revolute"><parent link="upper"/><child link="tip"/>
    <origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint>
</robot>
"""
MASSLESS = ("joint 'wrist': moves no mass: link 'tip' after it carries no mass (nor inertia "
            "about its axis), so its row of M(q) is zero and forward dynamics fail; give it an "
            "inertial or make the joint fixed")


def test_verify_names_the_joint_that_moves_no_mass(tmp_path):
    path = write(tmp_path / "tip.urdf", MASSLESS_TIP)
    result = run("verify", path, "--samples", "3", "--quiet")
    assert result.exit_code == 1, result.output
    assert result.stderr.splitlines() == [f"{WARNING}{path}: {MASSLESS}"]
    lines = result.stdout.splitlines()
    assert any(line.startswith("  FAIL M positive definite") for line in lines)
    assert f"  M is singular: {MASSLESS.replace(':', '', 1)}" in lines
    assert lines[-1] == "SOME CHECKS FAILED"


def test_generate_warns_about_the_joint_that_moves_no_mass(tmp_path):
    path = write(tmp_path / "tip.urdf", MASSLESS_TIP)
    result = run("generate", path, "--backend", "numpy", "-o", tmp_path / "out", "--quiet",
                 "--no-cache")
    assert result.exit_code == 0, result.output
    assert result.stderr.splitlines() == [f"{WARNING}{path}: {MASSLESS}"]
    assert (tmp_path / "out" / "arm_numpy.py").is_file()


def test_generate_strict_refuses_the_joint_that_moves_no_mass_and_writes_nothing(tmp_path):
    path = write(tmp_path / "tip.urdf", MASSLESS_TIP)
    result = run("generate", path, "--backend", "numpy", "-o", tmp_path / "out", "--quiet",
                 "--no-cache", "--strict")
    assert result.exit_code == 2, result.output
    assert result.stderr.splitlines() == [
        f"{ERROR}{path}: {MASSLESS} (refused under --strict)"]
    assert result.stdout == "" and not (tmp_path / "out").exists()


def test_mimic_joint_is_honoured_under_strict():
    """The Panda's second finger <mimic>s the first: a coupling, nothing refused; verify
    checks the 8 coordinates against Newton-Euler on the whole tree."""
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    path = robots / "panda_description/urdf/panda.urdf"
    result = run("verify", path, "--strict", "--samples", "2")
    assert result.exit_code == 0, result.output
    assert "mimic" not in result.stderr


# ----------------------------------------------------------------------------------------------
# Help and version
# ----------------------------------------------------------------------------------------------


def test_help_shows_examples():
    result = run("--help")
    assert result.exit_code == 0
    assert "Examples:" in result.stdout
    assert "  eomgen verify" in result.stdout
    assert "verify" in result.stdout.split("Commands:")[1]
    assert run("-h").stdout == result.stdout


def test_verify_help_shows_examples_and_options():
    result = run("verify", "--help")
    assert result.exit_code == 0
    assert "Examples:" in result.stdout
    assert "  eomgen verify\n" in result.stdout
    assert "eomgen verify ur5.urdf --samples 100 --seed 3" in result.stdout
    for option in ("--samples", "--seed", "--tolerance", "--strict", "--debug"):
        assert option in result.stdout


def test_generate_help_lists_every_registered_backend():
    """Issue 29: the help listed four of the seven backends, by hand; it lists the registry,
    so a backend registered later is listed too."""
    import dataclasses

    from eomgen.codegen import BACKENDS, available_backends

    def listed() -> list[str]:
        result = run("generate", "--help")
        assert result.exit_code == 0
        section = result.stdout.split("Backends (--backend", 1)[1].split("Options:", 1)[0]
        return [line.split()[0] for line in section.splitlines()[1:]
                if line.startswith("  ") and not line.startswith("   ")]

    backends = available_backends()
    assert listed() == list(backends) and len(backends) >= 7
    BACKENDS["extra"] = dataclasses.replace(backends["numpy"], name="extra")
    try:
        assert "extra" in listed()
    finally:
        del BACKENDS["extra"]


def test_a_bundled_example_name_is_a_description_in_every_command(tmp_path, monkeypatch):
    """Issue 29: `eomgen teach scara_rrp` said "no such file" although Python's
    eomgen.example_path("scara_rrp") works; every command's DESCRIPTION takes the name, and a
    real file of that name wins."""
    from eomgen.cli import main
    from eomgen.robots import EXAMPLES

    for name, command in main.commands.items():
        argument = next((p for p in command.params if p.name == "description"), None)
        assert argument is not None, name
        assert argument.process_value(click_context(command), "scara_rrp") == \
            EXAMPLES["scara_rrp"], name
    assert ", ".join(sorted(EXAMPLES)) in " ".join(run("--help").stdout.split())

    monkeypatch.chdir(tmp_path)
    taught = run("teach", "scara_rrp", "--format", "md", "-o", "handout", "--no-check", "--quiet")
    assert taught.exit_code == 0, taught.output
    assert (tmp_path / "handout" / "scara_rrp_handout.md").is_file()
    generated = run("generate", "elbow_rrr", "--backend", "numpy", "-o", "out", "--no-cache",
                    "--quiet")
    assert generated.exit_code == 0, generated.output
    assert (tmp_path / "out" / "elbow_rrr_numpy.py").is_file()

    (tmp_path / "scara_rrp").write_text("not a robot", encoding="utf-8")  # a file wins
    refused = run("verify", "scara_rrp")
    assert refused.exit_code == 2
    assert refused.stderr.startswith(f"{ERROR}scara_rrp: unknown file type ''")
    missing = run("verify", "scara")
    assert missing.exit_code == 2 and missing.stderr == (
        f"{ERROR}scara: no such file; did you mean 'scara_rrp'?\n")


def click_context(command):
    import click

    return click.Context(command)


def test_version():
    result = run("--version")
    assert result.exit_code == 0
    assert result.stdout == f"eomgen, version {eomgen.__version__}\n"


def test_unknown_option_is_a_usage_error():
    result = run("verify", "--no-such-option")
    assert result.exit_code == 2
    assert "No such option" in result.stderr
