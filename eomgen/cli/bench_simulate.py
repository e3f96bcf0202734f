"""``eomgen bench`` and ``eomgen simulate``: the command-line side of :mod:`eomgen.analysis`.

``--scene`` reduces the model by a scene file (``eomgen.scene``, ``eomgen.reduction``) before
anything is measured. Whether OUTPUT can be written is checked before the work
(:func:`eomgen.common.output.check_output_folder`); progress goes through :class:`eomgen.common.progress.Progress`
(stage lines with elapsed times in a log, a bar on a terminal, nothing with ``--quiet``).
The analysis modules (NumPy, SciPy, Matplotlib, the ``analysis`` extra) are imported when a
command runs, after its optional dependencies are checked.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import click

from ..errors import AnalysisError
from ..common.output import check_output_folder
from ..common.progress import HEARTBEAT_SECONDS, Progress, plural
from .handling import handle_errors
from .loading import load_reduced, output_stem
from .options import (description_argument, output_folder_option, quiet_option, scene_option,
                      strict_option)

#: ``--quiet`` of ``bench`` and ``simulate`` (a bar, never an updating line, on a terminal).
QUIET_HELP = "No progress on stderr (stage lines in a log, a bar on a terminal)."

#: ``--scene`` of ``bench`` and ``simulate``.
SCENE_HELP = ("Scene file (YAML): reduce the robot to what the scene moves first "
              "(e.g. examples/scenes/panda_fingers_locked.yaml).")


def _require(*modules: str) -> None:
    missing = [m for m in modules if importlib.util.find_spec(m) is None]
    if missing:
        raise AnalysisError(f"this command needs {', '.join(missing)}: "
                            "pip install 'eomgen[analysis]'")


def _floats(text: str | None, option: str) -> list[float] | None:
    if text is None:
        return None
    try:
        values = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise AnalysisError(f"{option}: expected comma-separated numbers, got {text!r}") from None
    if not values or not all(v == v and abs(v) != float("inf") for v in values):
        raise AnalysisError(f"{option}: expected finite comma-separated numbers, got {text!r}")
    return values


@click.command()
@description_argument()
@output_folder_option("eomgen_bench")
@click.option("--samples", default=50, show_default=True,
              help="Sampled states (errors are the largest over them).")
@click.option("--seed", default=0, show_default=True, help="Seed of the sampled states.")
@click.option("--repeats", default=7, show_default=True, help="Timing repeats per route.")
@click.option("--batch-size", default=1000, show_default=True,
              help="States per call of the batch routes.")
@quiet_option(QUIET_HELP)
@scene_option(SCENE_HELP)
@strict_option
@handle_errors
def bench(description, outdir, samples, seed, repeats, batch_size, quiet, strict,
          scene_path=None):
    """Time and accuracy of every evaluation route for DESCRIPTION.

    Routes: the generated NumPy module (one state, batch), the same program in float32 and
    over Python floats, the CasADi functions (SX, and the compiled C when a compiler is
    found), the fast C extension (one state, batch) when it compiles, eomgen's numeric
    Newton-Euler and Pinocchio (plain pin.rnea and pin.crba calls) when installed. Each evaluates
    inverse dynamics and the mass matrix on sampled states; errors are against a 40-digit
    mpmath reference. Writes bench_<robot>.md, .csv and .png (speed against error, Pareto
    front marked) into OUTPUT.

    \b
    Examples:
      eomgen bench
      eomgen bench ur5_robot.urdf --samples 100 -o build/bench
    """
    _require("matplotlib", "mpmath")
    if samples < 1 or repeats < 1 or batch_size < 1:
        raise AnalysisError("--samples, --repeats and --batch-size must be positive")
    check_output_folder(outdir)
    # NumPy, mpmath, Matplotlib (optional, checked above): only when the command runs
    from ..analysis.bench import prepare_bench, write_outputs

    progress = Progress(quiet, heartbeat=HEARTBEAT_SECONDS)
    model = load_reduced(description, scene_path, strict)[0]
    plan = prepare_bench(model, samples=samples, seed=seed, batch_size=batch_size,
                         repeats=repeats, log=progress)
    with progress.steps(plan.steps, "measuring") as steps:
        result = plan.run(steps)
    progress("writing the report and plot")
    paths = write_outputs(result, outdir, output_stem(model))
    progress.clear()
    click.echo(result.markdown())
    for path in paths:
        click.echo(str(path))

@click.command()
@description_argument()
@output_folder_option("eomgen_simulate")
@click.option("--duration", default=5.0, show_default=True, help="Simulated time [s].")
@click.option("--dt", "dts", default="1e-2,3e-3,1e-3", show_default=True,
              help="Steps of the fixed-step integrators [s], comma-separated.")
@click.option("--rtol", "rtols", default="1e-4,1e-6,1e-8", show_default=True,
              help="Relative tolerances of the adaptive integrators, comma-separated.")
@click.option("--integrators", "names", default="all", show_default=True,
              help="Comma-separated among euler, semi-implicit-euler, rk4, "
                   "implicit-midpoint, rk45, dop853; or all.")
@click.option("--q0", default=None, help="Initial joint positions, comma-separated "
                                         "(default: 1 rad or m per joint).")
@click.option("--qd0", default=None, help="Initial joint velocities (default: zero).")
@click.option("--baumgarte", "gains", default=None, metavar="KP,KD",
              help="Contacts: Baumgarte gains [1/s², 1/s] of the stabilised runs, for "
                   "every contact (default: the scene's, else 100,20).")
@click.option("--step-torque", default=5.0, show_default=True,
              help="Flexible joints: the step in the first motor's torque [N m] of the "
                   "link-against-motor-angle plot.")
@quiet_option(QUIET_HELP)
@scene_option(SCENE_HELP)
@strict_option
@handle_errors
def simulate(description, outdir, duration, dts, rtols, names, q0, qd0, gains, step_torque,
             quiet, strict, scene_path=None):
    """Integrate DESCRIPTION's dynamics (zero torque, no damping) with several integrators.

    Explicit Euler, semi-implicit Euler, RK4 and the implicit midpoint rule at every --dt;
    SciPy's RK45 and DOP853 at every --rtol. Reports wall time against energy drift and
    against the error of q versus a DOP853 reference at rtol = atol = 1e-12. Writes
    simulate_<robot>.md, .csv and .png into OUTPUT.

    With a scene that has loops, they are held (q0 closed by Newton, qd0 projected), with
    its contacts if any, and each integrator runs without and with Baumgarte: loop drift,
    contact drift and energy drift (docs/loops.md). With a scene that has contacts, the contacts are held (bilateral) where they are at
    q0, and each integrator (not the implicit midpoint) runs without and with Baumgarte
    stabilisation: constraint drift (position, orientation, velocity) and energy drift.
    With flexible joints (actuators with a stiffness), the 2n-state Spong model is
    integrated (SciPy's implicit Radau and BDF join the list), and flexible_step_<robot>.png
    plots link against motor angle after a step of --step-torque in the first motor.

    \b
    Examples:
      eomgen simulate --q0 2,2.5
      eomgen simulate panda.urdf --scene examples/scenes/panda_fingers_locked.yaml
      eomgen simulate --scene examples/contacts/planar_2link_wall.yaml --qd0 0.2,-0.1
      eomgen simulate examples/robots/flexible_2link.yaml --duration 1
    """
    _require("matplotlib", "scipy")
    # NumPy, SciPy, Matplotlib (optional, checked above): only when the command runs
    from ..analysis.simulate import System, integrators_named, run_study, write_outputs

    if not duration > 0 or duration == float("inf"):
        raise AnalysisError(f"--duration must be a positive number of seconds, got {duration}")
    step_list = _floats(dts, "--dt")
    rtol_list = _floats(rtols, "--rtol")
    if min(step_list) <= 0 or min(rtol_list) <= 0:
        raise AnalysisError("--dt and --rtol must be positive")
    gain_list = _floats(gains, "--baumgarte")
    if gain_list is not None and (len(gain_list) != 2 or min(gain_list) < 0):
        raise AnalysisError(f"--baumgarte: expected two non-negative numbers KP,KD, "
                            f"got {gains!r}")
    if not abs(step_torque) < float("inf"):
        raise AnalysisError(f"--step-torque must be a finite number, got {step_torque}")
    chosen = [n.strip() for n in names.split(",") if n.strip()]
    try:
        integrators_named(chosen, step_list, rtol_list)
    except ValueError as exc:
        raise AnalysisError(f"--integrators: {exc}") from None
    check_output_folder(outdir)
    progress = Progress(quiet, heartbeat=HEARTBEAT_SECONDS)
    model, report = load_reduced(description, scene_path, strict)
    contacts = report.contacts if report is not None else ()
    from ..model import flexible_indices  # SymPy: only when the command runs

    flexible = bool(flexible_indices(model)) and not contacts
    integrators = integrators_named(chosen, step_list, rtol_list, stiff=flexible)
    start = _floats(q0, "--q0")
    velocity = _floats(qd0, "--qd0")
    for values, option, names in ((start, "--q0", model.configuration_names),
                                  (velocity, "--qd0", model.joint_names)):
        if values is not None and len(values) != len(names):
            raise AnalysisError(f"{option}: {model.name} takes {len(names)} values "
                                f"({', '.join(names)}), got {len(values)}")
    from ..model.configuration import degenerate  # NumPy: only when the command runs

    problem = None if start is None else degenerate(start, model)
    if problem is not None:
        raise AnalysisError(f"--q0: {problem}")
    if model.loops:
        _simulate_loops(model, integrators, duration, start, velocity, gain_list, outdir,
                        progress)
        return
    if contacts:
        _simulate_contacts(model, contacts, integrators, duration, start, velocity,
                           gain_list, outdir, progress)
        return
    progress(f"deriving M, C, g and tau of {model.name} ({plural(model.dof, 'joint')})")
    header = []
    if flexible:
        # NumPy, SciPy (optional): only when the command runs
        import numpy as np

        from ..analysis.simulate_flexible import (FlexibleSystem, describe_stiffness,
                                                  flexible_start, plot_step, step_response)

        system = FlexibleSystem(model)
        links = np.full(model.dof, 1.0) if start is None else np.array(start)
        header.append(describe_stiffness(system, links))
        start = flexible_start(system, links)
        if velocity is not None:
            velocity = velocity + [0.0] * len(system.flexible)
    else:
        system = System(model)
    with progress.steps(len(integrators) + 1, "integrating") as steps:
        study = run_study(model, integrators, duration, start, velocity,
                          progress=lambda name: steps.update(1, name), system=system)
    progress("writing the report and plot")
    paths = write_outputs([study], outdir, f"simulate_{output_stem(model)}")
    if flexible:
        progress(f"step of {step_torque:g} N m in the first motor torque")
        response = step_response(model, links, step_torque, duration)
        png = Path(outdir) / f"flexible_step_{output_stem(model)}.png"
        plot_step(response, png)
        paths.append(png)
        md = paths[0]
        md.write_text("\n\n".join(header) + "\n\n" + md.read_text(encoding="utf-8")
                      + f"\n![link and motor angle after a step]({png.name})\n",
                      encoding="utf-8")
    progress.clear()
    for line in header:
        click.echo(line)
    click.echo(study.describe())
    click.echo(study.markdown_table())
    for path in paths:
        click.echo(str(path))


def _simulate_loops(model, integrators, duration, start, velocity, gains, outdir, progress):
    # NumPy, SciPy (optional): only when the command runs
    from ..analysis.simulate_loops import run_loop_study, write_loop_outputs

    with progress.steps(2 * len(integrators) + 1, "integrating") as steps:
        study = run_loop_study(model, integrators, duration, start, velocity, gains,
                               progress=lambda name: steps.update(1, name))
    progress("writing the report")
    _echo(study, write_loop_outputs(study, outdir, f"simulate_{output_stem(model)}"), progress)


def _echo(study, paths, progress) -> None:
    """A constrained study's description, table and files, on standard output."""
    progress.clear()
    click.echo(study.describe())
    click.echo(study.markdown_table())
    for path in paths:
        click.echo(str(path))


def _simulate_contacts(model, contacts, integrators, duration, start, velocity, gains,
                       outdir, progress):
    # NumPy, SciPy (optional): only when the command runs
    from ..analysis.simulate_contacts import run_contact_study, write_contact_outputs

    with progress.steps(2 * len(integrators) + 1, "integrating") as steps:
        study = run_contact_study(model, contacts, integrators, duration, start, velocity,
                                  None if gains is None else tuple(gains),
                                  progress=lambda name: steps.update(1, name))
    progress("writing the report and plot")
    _echo(study, write_contact_outputs(study, outdir, f"simulate_{output_stem(model)}"),
          progress)
