"""CLI: ``spatialmech defects`` (paper A's defect judgement for any 1-DOF linkage)."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from .. import api as sm
from ..errors import InputError
from .common import SEED_MAX, check_output_dir, emit_json, json_option, load_model

#: Largest --monte-carlo: each sample is a whole defect analysis (seconds to tens of seconds).
MAX_MONTE_CARLO = 1000


@click.command()
@click.argument("model")
@click.option("--positions", "positions_file", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="TOML file of task positions ([[positions]] with point and euler/matrix); default: the model's own.")
@click.option("--driver", "drivers", multiple=True, help="Candidate driver (repeatable; default: every base-joint freedom).")
@click.option("--pose-tol", type=float, default=None,
              help="Position tolerance for circuit membership (length; default 2% of the size).")
@click.option("--angle-tol-deg", type=float, default=1.0, show_default=True, help="Angle tolerance for circuit membership (deg).")
@click.option("--monte-carlo", type=int, default=0, show_default=True, help="Samples of a perturbation check of the verdicts.")
@click.option("--precision", type=float, default=5e-4, show_default=True, help="Printed precision of lengths for --monte-carlo.")
@click.option("--seed", type=click.IntRange(0, SEED_MAX), default=0, show_default=True, help="Seed of the Monte-Carlo check.")
@click.option("--plot", "plot_dir", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Write the figures into this directory.")
@json_option
def defects(model, positions_file, drivers, pose_tol, angle_tol_deg, monte_carlo, precision, seed, plot_dir, as_json):
    """Circuit, branch and order defects of a 1-DOF linkage for its task positions; drivers
    that can be used; a dual-drive plan when no single driver can.

    \b
    Examples:
      spatialmech defects five-cs-1
      spatialmech defects five-cs-3 --json --plot figs
      spatialmech defects my-linkage.toml --positions my-positions.toml --driver A0
    """
    if monte_carlo > MAX_MONTE_CARLO:
        raise InputError(f"--monte-carlo: at most {MAX_MONTE_CARLO} samples (each is a whole defect analysis), "
                         f"got {monte_carlo}")
    check_output_dir(plot_dir, "--plot")
    mech = load_model(model)
    say = None if as_json else (lambda done, total, msg: click.echo(f"  ... {msg}", err=True))
    res = sm.defects(mech, positions_file, drivers=list(drivers) or None, pose_tol=pose_tol, angle_tol_deg=angle_tol_deg,
                     monte_carlo=monte_carlo, seed=seed, precision=precision, plot=plot_dir, progress=say)
    paths = res.figures
    if as_json:
        emit_json("defects", mech, {**res.to_dict(), "figures": [str(p) for p in paths]})
        return
    circuits = "; ".join("{" + ", ".join(f"P{j}" for j in c) + "}" for c in res.circuits)
    click.echo(f"{mech.name}: {len(res.circuits)} circuit(s): {circuits}")
    click.echo(f"  circuit defect: {'YES' if res.circuit_defect else 'no'}   order defect: {'YES' if res.order_defect else 'no'}"
               + ("" if res.circuit_defect else f"   (positions met in order {', '.join(f'P{j}' for j in res.order)})"))
    click.echo(f"  DJ: {res.dj_method}; membership tolerance {res.tolerances['pose']:.3g} {mech.length_unit}, "
               f"{res.tolerances['angle_deg']:g} deg")
    names = [p.name for p in res.positions]
    for j, f in enumerate(res.fits):
        if np.hypot(f.position_error / res.tolerances["pose"], np.degrees(f.angle_error) / res.tolerances["angle_deg"]) > 1:
            click.echo(f"  note: the pose of {names[j] or f'P{j + 1}'} is {f.position_error:.3g} {mech.length_unit} and "
                       f"{np.degrees(f.angle_error):.3g} deg from the nearest closed configuration (beyond the "
                       "membership tolerance); the analysis uses that configuration")
    for v in res.drivers:
        signs = " ".join("+" if s > 0 else ("-" if s < 0 else "0") for s in v.signs)
        spans = [f"P{b.between[0]}-P{b.between[1]}" if b.between else "?" for b in v.branch_points]
        where = ", ".join(x + (f" x{spans.count(x)}" if spans.count(x) > 1 else "")
                          for x in dict.fromkeys(spans))  # "P6-P7 x2": two zeros between P6 and P7
        verdict = ("usable" if v.usable
                   else ("branch defect" + (f" ({where})" if where else "") if v.branch_defect else "not usable"))
        extra = f"  min sigma on path {v.min_sigma_on_path:.2e}" if v.min_sigma_on_path is not None else ""
        click.echo(f"  {v.driver:>8s}  {signs}   {verdict}{extra}")
    if res.usable_drivers:
        click.echo(f"  usable drivers: {', '.join(res.usable_drivers)}")
    if res.plan:
        click.echo("  multi-drive plan:")
        for st in res.plan:
            sw = f"; switch within arc {st.switch_window[0]:.3f}..{st.switch_window[1]:.3f}" if st.switch_window else ""
            click.echo(f"    {st.driver} from arc {st.start_arc:.3f} to {st.end_arc:.3f}{sw}")
    if res.min_closure_sigma is not None:
        b = res.min_closure_sigma_between
        click.echo(f"  closest approach to a singularity of the linkage on the path: sigma = {res.min_closure_sigma:.2e}"
                   + (f" between P{b[0]} and P{b[1]}" if b else ""))
    if res.robustness:
        r = res.robustness
        click.echo(f"  Monte-Carlo ({r['samples']} samples, seed {r['seed']}, precision {r['precision_length']:g}): "
                   f"same verdict in {r['same_verdict']}, failed {r['failed']}")
    for p in paths:
        click.echo(f"  wrote {p}")
