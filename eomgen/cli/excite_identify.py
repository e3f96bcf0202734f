"""``eomgen excite`` (an exciting trajectory, simulated as identification data) and
``eomgen identify`` (base parameters from measurements): the command-line side of
:mod:`eomgen.identification`.

Output is checked before any work and written all or nothing (:mod:`eomgen.common.output`). The
identification modules (NumPy, SciPy, cvxpy for ``--physical``) and the regressor (SymPy) are
imported when a command runs, after its optional dependencies are checked.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import click

from ..errors import IdentificationError, ParameterError
from ..common.output import GeneratedFile, check_output_file, check_output_folder, write_atomically
from ..common.progress import HEARTBEAT_SECONDS, Progress, plural
from .handling import handle_errors
from .loading import load_reduced, output_stem
from .options import (description_argument, output_file_option, output_folder_option,
                      quiet_option, scene_option, strict_option)


#: What the actuator terms add to the efforts, for the excite summary.
_TERM_WORDS = {"armature": "armature", "viscous": "viscous friction",
               "coulomb": "Coulomb friction"}


def _terms(model, friction: bool | None) -> tuple[str, ...]:
    """The actuator columns (:func:`eomgen.regressor.identification_terms`), found before any
    work so that a flexible joint is refused at once."""
    # SymPy: only when a command runs
    from ..regressor import identification_terms

    return identification_terms(model, friction)


def _regressor(model, terms: tuple[str, ...], progress: Progress):
    # SymPy: only when a command runs
    from ..regressor import base_parameters, derive_regressor

    progress(f"deriving the regressor of {model.name} ({plural(model.dof, 'joint')})")
    reg = derive_regressor(model, terms)
    progress("finding the base parameters")
    return reg, base_parameters(reg)


def _friction_option(what: str):
    return click.option(
        "--friction/--no-friction", default=None,
        help="Viscous and Coulomb friction columns (FV<k>, FC<k>). Default: those the "
             "description declares (URDF <dynamics damping friction>, YAML or scene "
             "actuators), as the generated regressor has them; --friction adds both for "
             f"every joint; --no-friction leaves them out{what}. A declared armature (IA<k>) "
             "is always kept.")


@click.command()
@description_argument(required=True)
@output_file_option("CSV file to write.", default="excitation.csv")
@click.option("--duration", default=10.0, show_default=True,
              help="Length [s] of the record, one period of the Fourier series.")
@click.option("--samples", default=500, show_default=True, help="Samples over the record.")
@click.option("--harmonics", default=3, show_default=True, help="Harmonics per joint.")
@click.option("--amplitude", default=1.0, show_default=True,
              help="Bound on |q_j(t)| [rad or m]; a URDF's joint limits bound q too.")
@click.option("--max-velocity", type=float, default=None,
              help="Bound on |qd_j(t)| [rad/s or m/s] for every joint; a URDF's velocity "
                   "limits too (the tighter applies) [default: only those].")
@click.option("--max-acceleration", type=float, default=None,
              help="Bound on |qdd_j(t)| [rad/s² or m/s²] for every joint [default: none].")
@click.option("--noise", default=0.0, show_default=True,
              help="Gaussian effort noise, as a fraction of each joint's RMS effort "
                   "(0.01: 1 %).")
@click.option("--seed", default=0, show_default=True,
              help="Seed of the optimiser's start and of the noise.")
@click.option("--positions-only", is_flag=True,
              help="Write only t, q_<joint> and tau_<joint> (identify then differentiates "
                   "q through a zero-phase filter).")
@_friction_option(" and simulates without friction")
@scene_option()
@quiet_option()
@strict_option
@handle_errors
def excite(description, output, duration, samples, harmonics, amplitude, max_velocity,
           max_acceleration, noise, seed, positions_only, friction, scene_path, quiet,
           strict):
    """Simulate an exciting trajectory of DESCRIPTION and write it as identification data.

    A finite Fourier series per joint (Swevers et al. 1997) whose coefficients minimise the
    condition number of the base regressor (L-BFGS-B from a seeded random start), sampled
    evenly over --duration. The coefficients are boxed so that at every instant |q_j| ≤
    --amplitude, q_j within the joint's <limit> lower/upper (URDF), |qd_j| ≤
    --max-velocity and the URDF velocity limit, |qdd_j| ≤ --max-acceleration; a joint with
    no room to move is an error. Efforts from eomgen's numeric
    Newton-Euler with the description's parameters, plus the armature, viscous and Coulomb
    friction its joints declare (see --friction), plus --noise. Columns: t, q_<joint>,
    qd_<joint>, qdd_<joint>, tau_<joint> (JOINT_NAMES order). A model with quaternion
    joints (a free flyer, ball joints) moves in a chart (a ball joint's three angles
    Rx Ry Rz, the free flyer's position and angles, bounded as joints are); its q_ columns
    are CONFIGURATION_NAMES (q_base_x ... q_base_qw), the others its NV velocity
    coordinates (qd_base_vx: the root twist), and its efforts are Y(q, v, v̇) π.

    \b
    Examples:
      eomgen excite eomgen/robots/puma560_dh.yaml -o puma.csv --noise 0.01
      eomgen identify eomgen/robots/puma560_dh.yaml puma.csv -o puma_id
    """
    if importlib.util.find_spec("scipy") is None:
        raise IdentificationError("eomgen excite needs scipy: pip install 'eomgen[identify]'")
    # NumPy, SciPy (optional, checked above): only when the command runs
    from ..identification.estimation import (excitation_trajectory, measurements_csv,
                                             motion_bounds, simulate_measurements)
    from ..identification.excitation import EXCITATION_ITERATIONS
    from ..regressor import declared_actuator_terms  # SymPy: only when the command runs

    if not duration > 0 or duration == float("inf"):
        raise IdentificationError(f"--duration must be a positive number of seconds, got "
                                  f"{duration}")
    if samples < 1 or harmonics < 1:
        raise IdentificationError("--samples and --harmonics must be positive")
    if not amplitude > 0 or not noise >= 0 or noise == float("inf"):
        raise IdentificationError("--amplitude must be positive and --noise non-negative")
    check_output_file(output)
    progress = Progress(quiet, heartbeat=HEARTBEAT_SECONDS)
    model, _ = load_reduced(description, scene_path, strict)
    if positions_only and model.nq > model.dof:
        raise IdentificationError(f"{description}: --positions-only: a model with quaternion "
                                  "joints needs its qd_, qdd_ columns (a quaternion's rate is "
                                  "not v)")
    terms = _terms(model, friction)
    limits = {}
    if description.suffix.lower() == ".urdf":
        from ..parsers.urdf import joint_limits  # the parsers (SymPy): only when a command runs

        limits = joint_limits(description)
    bounds = motion_bounds(model.joint_names, amplitude, limits, max_velocity,
                           max_acceleration, str(description))
    reg, base = _regressor(model, terms, progress)
    progress(f"optimising a {harmonics}-harmonic Fourier trajectory "
             f"({model.dof * (2 * harmonics + 1)} coefficients)")
    with progress.steps(EXCITATION_ITERATIONS, "optimising") as steps:
        ex = excitation_trajectory(reg, base, period=duration, harmonics=harmonics,
                                   seed=seed, bounds=bounds, maxiter=EXCITATION_ITERATIONS,
                                   progress=lambda line: steps.update(1, line))
    progress(f"simulating {plural(samples, 'sample')}")
    t = [k * duration / samples for k in range(samples)]
    data = simulate_measurements(model, ex.trajectory, t, noise=noise, seed=seed,
                                 actuators=reg.actuators)
    [path] = write_atomically([GeneratedFile(output.name,
                                             measurements_csv(data, not positions_only))],
                              output.parent)
    progress.clear()
    drives = [_TERM_WORDS[term] for term in reg.actuators
              if term in declared_actuator_terms(model)]
    drives = ", ".join(drives[:-1]) + " and " * (len(drives) > 1) + "".join(drives[-1:])
    click.echo(f"excitation of {model.name}: cond(Y_base) {ex.initial_condition:.4g} at the "
               f"random start, {ex.condition:.4g} optimised ({ex.evaluations} evaluations)"
               + (f"; efforts with the description's {drives}" if drives else ""))
    click.echo(str(path))


@click.command()
@description_argument(required=True)
@click.argument("data", type=click.Path(dir_okay=False, path_type=Path))
@output_folder_option("eomgen_identify")
@click.option("--physical", is_flag=True,
              help="Also fit physically consistent parameters (every pseudo-inertia "
                   "positive semi-definite; needs cvxpy: pip install 'eomgen[identify]').")
@_friction_option(" (the description column then has no friction either)")
@click.option("--cutoff", default=None, type=float,
              help="Cut-off [Hz] of the zero-phase low-pass filter. DATA without qd_, "
                   "qdd_ columns: q is filtered and differentiated [default: sampling "
                   "frequency / 10]. DATA with them: q, qd, qdd and tau are all filtered, "
                   "ends trimmed, decimated [default: no filtering].")
@scene_option()
@quiet_option()
@strict_option
@handle_errors
def identify(description, data, outdir, physical, friction, cutoff, scene_path, quiet,
             strict):
    """Estimate DESCRIPTION's base parameters from the measurements in DATA (CSV).

    DATA's header names its columns: t, q_<joint>, qd_<joint>, qdd_<joint>, tau_<joint>
    (t optional), or t, q_<joint>, tau_<joint> (q̇, q̈ then come from a zero-phase
    Butterworth filter and central differences), joints as in the description (after
    --scene). A model with quaternion joints names q_ after CONFIGURATION_NAMES (q_base_qx,
    ...) and the rest after its velocity coordinates (qd_base_vx, ...), and needs the qd_,
    qdd_ columns (v and v̇, Pinocchio's). With qd_, qdd_ columns and --cutoff, all four signals go through that filter
    (t needed). Weighted least squares (Gautier) with standard deviations and the condition
    number; --physical adds a fit with positive semi-definite pseudo-inertias. The
    friction (and armature) the description declares is fitted too (see --friction), and
    the report's description column shows the declared values. Writes
    identify_<robot>.md (table), .csv (estimates) and .png (predicted against measured
    efforts) into OUTPUT.

    \b
    Examples:
      eomgen excite eomgen/robots/puma560_dh.yaml -o puma.csv --noise 0.01
      eomgen identify eomgen/robots/puma560_dh.yaml puma.csv -o puma_id --physical
    """
    # NumPy (and cvxpy for --physical): only when the command runs
    from ..identification.estimation import (observation_matrix, physical_fit,
                                             read_measurements, weighted_least_squares)
    from ..identification.report import IdentificationReport
    from ..model.configuration import quaternion_indices
    from ..regressor import description_values  # SymPy: only when the command runs

    if physical and importlib.util.find_spec("cvxpy") is None:
        raise IdentificationError("--physical needs cvxpy: pip install 'eomgen[identify]'")
    check_output_folder(outdir)
    progress = Progress(quiet, heartbeat=HEARTBEAT_SECONDS)
    model, _ = load_reduced(description, scene_path, strict)
    terms = _terms(model, friction)
    progress(f"reading {data}")
    measured = read_measurements(data, model.joint_names, cutoff,
                                 model.configuration_names if model.nq > model.dof else None,
                                 list(quaternion_indices(model)))
    reg, base = _regressor(model, terms, progress)
    progress(f"stacking the base regressor over {plural(measured.N, 'sample')}")
    W = observation_matrix(reg, base.base, measured.q, measured.qd, measured.qdd)
    estimate = weighted_least_squares(W, measured.tau, str(data))
    fit = None
    if physical:
        progress("solving the physically consistent fit (SDP)")
        fit = physical_fit(reg, base, W, measured.tau, estimate.sigma, str(data))
    try:
        reference = base.beta(description_values(reg))
    except ParameterError:
        reference = None
    names, expressions = zip(*[(name, str(expr)) for name, expr in base.expressions()])
    report = IdentificationReport(model.name, str(data), names, expressions, measured,
                                  estimate, fit, reference)
    progress("writing the report and plot")
    paths = write_atomically(report.files(f"identify_{output_stem(model)}"), outdir)
    progress.clear()
    click.echo(report.markdown())
    for path in paths:
        click.echo(str(path))
