"""The reproduction report: ``results.json`` and a self-contained ``index.html``.

Each paper claim is a row: what the paper says, what the project computes, whether it
reproduces, and why not when it does not.  This module only gathers and renders; the numbers
come from the analyses.
"""

from __future__ import annotations

import html
import sys
import json
from dataclasses import asdict, dataclass
from pathlib import Path

import click

from .. import __version__, catalog
from ..analysis.mobility import mobility_modes
from ..catalog.papers import THREE_RRR_TABLE2, THREE_SPS_SMPU_MODES


@dataclass(frozen=True)
class Claim:
    paper: str
    claim: str
    paper_value: str
    ours: str
    reproduced: bool
    note: str = ""


def _same_motion(a: str, b: str) -> bool:
    """Motion names compared as sets of elementary motions (order-free: 'RzRy' == 'RyRz')."""
    split = lambda s: sorted(s[i : i + 2] for i in range(0, len(s), 2))
    return split(a) == split(b)


def mobility_claims(results: dict[str, list]) -> list[Claim]:
    """The papers' mobility claims checked against computed results (by model name)."""
    claims = []
    r = results["four-sps-cu"][0]
    ours = f"n={r.n}, g={r.g}, sum f={r.sum_f}, lambda={r.lam}, v={r.v}, xi={r.xi}, M={r.dof} ({r.motion})"
    ok = (r.n, r.g, r.sum_f, r.lam, r.v, r.xi, r.dof) == (11, 14, 32, 0, 0, 4, 4) and _same_motion(r.motion, "RxRyRzTz")
    claims.append(Claim("B", "4-SPS/CU mobility (eq 4, section 3)", "n=11, g=14, sum f=32, lambda=0, v=0, xi=4, M=4 (3R + Tz)", ours, ok))
    by_mode = {x.mode: x for x in results["three-rrr-sm"]}
    for driven, motion in THREE_RRR_TABLE2.items():
        x = by_mode["+".join(driven)]
        ok = x.dof == len(driven) and _same_motion(x.motion, motion) and x.d == 3
        note = "table 2 prints R7 -> Rx; R7 drives Rz (typo, conventions.md)" if driven == ("R7",) else ""
        claims.append(
            Claim("C", f"3-RRR metamorphic joint, drive {'+'.join(driven)} (table 2, eqs 10/13/16)",
                  f"M={len(driven)}, {motion}", f"M={x.dof} ({x.d}({x.n}-{x.g}-1)+{x.sum_f}+{x.v}-{x.xi}), {x.motion}", ok, note)
        )
    by_mode = {x.mode: x for x in results["three-sps-smpu"]}
    for driven, motion in THREE_SPS_SMPU_MODES.items():
        x = by_mode["+".join(driven) if driven else "Sm-locked"]
        ok = x.dof == 3 + len(driven) and _same_motion(x.motion, motion)
        claims.append(
            Claim("C", f"3-SPS/SmPU, Sm rotations driven: {', '.join(driven) or 'none'} (section 5)",
                  f"{3 + len(driven)} DOF, {motion}", f"{x.dof} DOF, {x.motion}", ok,
                  "generic dimensions (the paper gives none)")
        )
    for k in (1, 2, 3):
        x = results[f"five-cs-{k}"][0]
        claims.append(Claim("A", f"5-CS linkage {k} is a one-degree-of-freedom linkage", "1", f"{x.dof} (instantaneous {x.dof_instantaneous})", x.dof == 1 == x.dof_instantaneous))
    return claims


def _table(rows: list[dict], cols: list[str]) -> str:
    head = "".join(f"<th>{html.escape(c)}</th>" for c in cols)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(str(r.get(c, '')))}</td>" for c in cols) + "</tr>" for r in rows
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


_CSS = """
body{font-family:system-ui,sans-serif;margin:2em auto;max-width:1100px;color:#222}
table{border-collapse:collapse;margin:1em 0;font-size:14px}
td,th{border:1px solid #ccc;padding:4px 8px;text-align:left;vertical-align:top}
th{background:#f3f3f3} .ok{color:#176f2c;font-weight:bold} .no{color:#b3261e;font-weight:bold}
code{background:#f5f5f5;padding:0 3px}
"""


def render_html(data: dict) -> str:
    claims = data["claims"]
    crow = "".join(
        f"<tr><td>{html.escape(c['paper'])}</td><td>{html.escape(c['claim'])}</td><td>{html.escape(c['paper_value'])}</td>"
        f"<td>{html.escape(c['ours'])}</td><td class='{'ok' if c['reproduced'] else 'no'}'>"
        f"{'reproduced' if c['reproduced'] else 'NOT reproduced'}</td><td>{html.escape(c['note'])}</td></tr>"
        for c in claims
    )
    mob_rows = [
        {"model": m, **{k: v for k, v in r.items() if k in ("mode", "dof", "dof_instantaneous", "gk_classic", "motion", "lambda", "d", "n", "g", "sum_f", "v", "xi")}}
        for m, rs in data["mobility"].items() for r in rs
    ]
    cols = ["model", "mode", "dof", "dof_instantaneous", "gk_classic", "motion", "lambda", "d", "n", "g", "sum_f", "v", "xi"]
    n_ok = sum(c["reproduced"] for c in claims)
    return f"""<!doctype html><html><head><meta charset="utf-8"><title>spatialmech reproduction report</title>
<style>{_CSS}</style></head><body>
<h1>spatialmech reproduction report</h1>
<p>spatialmech {html.escape(data['version'])}. {n_ok} of {len(claims)} claims reproduced.</p>
<h2>Claims of the papers</h2>
<table><thead><tr><th>paper</th><th>claim</th><th>paper</th><th>spatialmech</th><th>verdict</th><th>note</th></tr></thead>
<tbody>{crow}</tbody></table>
<h2>Mobility of every ready-made model</h2>
<p>Modified Kutzbach-Grübler formula <code>M = d(n - g - 1) + &Sigma;f + v - &xi;</code> from the limbs' screw
systems at the reference configuration; <code>dof_instantaneous</code> is the independent numerical check
(rank of the loop-closure Jacobian at a generic configuration); <code>gk_classic</code> the uncorrected count.</p>
{_table(mob_rows, cols)}
</body></html>
"""


def build_demo(out: Path, *, progress: bool = True) -> dict:
    """Run every reproduction and write ``out/results.json`` and ``out/index.html``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    names = catalog.names()
    results = {}
    with click.progressbar(names, label="mobility", file=sys.stderr, hidden=not progress,
                           item_show_func=lambda n: n or "") as bar:
        for name in bar:
            results[name] = mobility_modes(catalog.build(name))
    claims = mobility_claims(results)
    data = {
        "version": __version__,
        "claims": [asdict(c) for c in claims],
        "mobility": {n: [r.to_dict() for r in rs] for n, rs in results.items()},
    }
    (out / "results.json").write_text(json.dumps(data, indent=2), encoding="utf-8")
    (out / "index.html").write_text(render_html(data), encoding="utf-8")
    return data
