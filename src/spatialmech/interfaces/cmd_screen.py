"""CLI: ``spatialmech screen`` (defect screening of 5-CS linkages from a seven-position CS dyad
family, on Dask, into a Parquet dataset; ``sm.screen``, :mod:`spatialmech.services.screening`)."""

from __future__ import annotations

from pathlib import Path

import click

from .. import api as sm
from ..errors import require
from .common import SEED_MAX, emit_json, json_option

__all__ = ["screen"]


@click.command()
@click.argument("task", default="five-cs-positions")
@click.option("--out", "out", required=True, type=click.Path(path_type=Path),
              help="Parquet dataset directory (e.g. screen.parquet); rerunning into it with the same arguments resumes.")
@click.option("--candidates", type=click.IntRange(min=1, max=10_000_000), default=1000, show_default=True,
              help="Number of candidate 5-CS linkages (all combinations when the pool has fewer).")
@click.option("--density", type=click.FloatRange(min=0.0, min_open=True, max=100.0), default=0.5, show_default=True,
              help="Dyads sampled per unit nondimensional arc length of the family.")
@click.option("--workers", type=click.IntRange(min=0, max=512), default=None,
              help="Local Dask worker processes (default: one per core; 0: serial in this process, no Dask).")
@click.option("--scheduler", default=None, help="Address of an existing Dask scheduler (e.g. tcp://10.0.0.5:8786).")
@click.option("--top", type=click.IntRange(min=0, max=1000), default=5, show_default=True,
              help="Write the best K usable linkages as model files (OUT/_top/rank-KK.toml).")
@click.option("--rank-by", type=click.Choice(["singularity", "slide"]), default="singularity", show_default=True,
              help="singularity: the largest distance to a singularity along the task path first, then the smallest "
                   "C-slide stroke; slide: the smallest stroke first.")
@click.option("--seed", type=click.IntRange(0, SEED_MAX), default=0, show_default=True,
              help="Seed of the family's random starts and of the sample.")
@click.option("--starts", type=click.IntRange(min=1, max=5000), default=60, show_default=True,
              help="Random starts of the family synthesis.")
@click.option("--separation", type=click.FloatRange(min=0.0), default=0.5, show_default=True,
              help="Smallest nondimensional distance between two limbs of a candidate.")
@click.option("--chunk-size", type=click.IntRange(min=1, max=100_000), default=20, show_default=True,
              help="Candidates per Parquet file and per Dask task.")
@json_option
def screen(task, out, candidates, density, workers, scheduler, top, rank_by, seed, starts, separation, chunk_size, as_json):
    """Defect screening of 5-CS linkages for seven task positions (paper A's workflow at scale).

    TASK is `five-cs-positions` (paper A table 9, the default), a positions TOML file, or a
    model with seven task positions.  The CS dyad family is sampled, candidate linkages of five
    dyads are formed, and each is judged in stages: assembly at the positions, DJ sign changes
    at the positions for every driver (fast rejection), then the defect analysis of `spatialmech
    defects` (circuit, order and branch defects).  Verdicts stream into the Parquet dataset
    OUT; the usable linkages are ranked by their distance to a singularity along the task path,
    then their total C slide, and the best are written as model files that `defects`, `view`
    and `report` accept.

    \b
    Examples:
      spatialmech screen five-cs-positions --candidates 1000 --out screen.parquet --top 5
      spatialmech screen my-7-positions.toml --candidates 200 --workers 0 --out s.parquet --json
      spatialmech screen --candidates 100000 --scheduler tcp://10.0.0.5:8786 --out big.parquet
    """
    require("screen", "distributed", "pyarrow", what="screening")
    def say(done, total, msg):
        click.echo(f"  ... {msg}", err=True)

    try:
        summary = sm.screen(task, out, candidates=candidates, density=density, seed=seed, starts=starts,
                            separation=separation, chunk_size=chunk_size, workers=workers, scheduler=scheduler,
                            top=top, rank_by=rank_by, progress=say)
    except KeyboardInterrupt:
        click.echo(f"interrupted: the chunks written so far are kept in {out}; rerun the same command to resume",
                   err=True)
        raise SystemExit(130) from None
    d = summary.to_dict()
    source = summary.positions_source
    if as_json:
        emit_json("screen", None, d, length_unit="unit")
        return
    st = summary.rejected_by_stage
    rate = summary.rate
    lines = [
        f"screen of 5-CS linkages for the 7 positions of {source}",
        f"  family: {summary.family['n_branches']} branches, {summary.family['n_points']} points "
        f"({summary.family.get('source', 'synthesised')}); pool: "
        f"{summary.pool['dyads']} dyads; candidates: {summary.candidates} ({summary.mode})",
        f"  judged {summary.judged} ({summary.judged_this_run} by this run, {summary.chunks_resumed} of "
        f"{summary.chunks} chunks resumed) in {summary.seconds:.1f} s"
        + (f", {rate:.2f} candidates/s" if rate else "") + f" on {summary.scheduler}"
        + (f", {summary.workers} workers" if summary.workers else ""),
        f"  rejected: assembly {st['assembly']}, DJ sign change at the positions {st['dj_signs']}, "
        f"circuit/order/branch defects {st['circuits']}, errors {st['error']}",
        f"  usable: {summary.usable}",
    ]
    for t in summary.top:
        lines.append(f"  #{t['place']}: candidate {t['candidate']} (dyads {t['dyads']}), drivers "
                     f"{', '.join(t['usable_drivers'])}; min sigma on the path {t['min_sigma_on_path']:.3g} "
                     f"({t['best_driver']}), slide stroke {t['stroke_len']:.4g} -> {t['model_file']}")
    if summary.note:
        lines.append(f"  note: {summary.note}")
    lines.append(f"  dataset: {summary.out} (Parquet; read it with pyarrow.parquet.read_table)")
    click.echo("\n".join(lines))
