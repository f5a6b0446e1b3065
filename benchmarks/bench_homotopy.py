"""Benchmark: forward position by homotopy continuation (kinematics/homotopy/study.py) against
PHCpack's blackbox solver on the same polynomial system, measured in the same run.

    python benchmarks/bench_homotopy.py [--json] [--quick]

Targets of the homotopy issue: every solution of the Stewart platform faster than PHCpack's
blackbox solver (goal: under 2 s), and a parameter-homotopy re-solve for new leg lengths under
50 ms (it reuses the cached generic solve, ``resolve_cached``), reported with
``resolve_speedup``, the first solve's time over the re-solve's median in the same run.
Cases: the ready-made stewart-6sps (a symmetric geometry: 28 generic solutions) and a random
general 6-6 platform (40).  ``phc`` is Debian's phcpack; without it that baseline is
skipped and said so.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from spatialmech import catalog
from spatialmech.kinematics.homotopy import study as hc

TARGET_FIRST_S = 2.0
TARGET_RESOLVE_MS = 50.0


def phc_blackbox(sysm, values, c) -> tuple[float, int] | None:
    """Seconds of ``phc -b`` on the system and its number of regular solutions (None: no phc)."""
    if shutil.which("phc") is None:
        return None
    with tempfile.TemporaryDirectory() as d:
        src, out = Path(d) / "in.txt", Path(d) / "out.txt"
        src.write_text(hc.phc_input(sysm, values, c))
        t = time.perf_counter()
        subprocess.run(["phc", "-b", str(src), str(out)], check=True, capture_output=True, timeout=600)
        dt = time.perf_counter() - t
        return dt, int(re.findall(r"Number of regular solutions\s*:\s*(\d+)", out.read_text())[-1])


def case(name: str, sysm, legs: np.ndarray, resolves: int, rng: np.random.Generator, phc: bool) -> dict:
    hc.clear_cache()
    t = time.perf_counter()
    first = hc.homotopy_forward(sysm, legs)
    t_first = time.perf_counter() - t
    times, cached = [], True
    for _ in range(resolves):
        new = legs * (1.0 + 0.02 * rng.standard_normal(len(legs)))
        t = time.perf_counter()
        again = hc.homotopy_forward(sysm, new)
        times.append(time.perf_counter() - t)
        cached &= bool(again.cached)
    med = float(np.median(times)) if times else None
    out = {"case": name, "n_generic": first.n_generic, "n_real": first.count("real"), "complete": first.complete,
           "first_solve_s": t_first, "resolve_median_ms": 1000 * med if med else None,
           "resolve_cached": cached, "resolve_speedup": t_first / med if med else None}
    if phc:
        got = phc_blackbox(sysm, legs, np.random.default_rng(3).normal(size=8))
        out["phc_blackbox_s"], out["phc_regular"] = got if got else (None, None)
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--quick", action="store_true", help="one case, two re-solves, no PHCpack (smoke test)")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(0)
    mech = catalog.build("stewart-6sps")
    cases = [case("stewart-6sps", hc.stewart_system(mech), np.full(6, 1.2), 2 if args.quick else 10, rng,
                  not args.quick)]
    if not args.quick:
        g = np.random.default_rng(7)
        sysm = hc.system_from_points(g.normal(size=(6, 3)), g.normal(size=(6, 3)) * 0.7 + [0, 0, 1.5])
        legs = np.linalg.norm(sysm.platform - sysm.base, axis=1) * 1.05
        cases.append(case("random 6-6", sysm, legs, 10, rng, True))
    for c in cases:
        c["first_met"] = c["first_solve_s"] < TARGET_FIRST_S and (c.get("phc_blackbox_s") is None
                                                                   or c["first_solve_s"] < c["phc_blackbox_s"])
        c["resolve_met"] = c["resolve_median_ms"] is not None and c["resolve_median_ms"] < TARGET_RESOLVE_MS
    out = {"cases": cases, "targets": {"first_solve_s": TARGET_FIRST_S, "resolve_ms": TARGET_RESOLVE_MS},
           "phc": shutil.which("phc") is not None}
    if args.json:
        print(json.dumps(out, indent=2))
        return out
    word = {True: "met", False: "NOT met"}
    for c in cases:
        phc_txt = (f"PHCpack blackbox {c['phc_blackbox_s']:.1f} s ({c['phc_regular']} regular)"
                   if c.get("phc_blackbox_s") else "PHCpack not run")
        print(f"{c['case']:14s} {c['n_generic']} generic solutions, {c['n_real']} real, complete {c['complete']}")
        print(f"  first solve    {c['first_solve_s']:.2f} s vs {phc_txt} (target < {TARGET_FIRST_S:g} s and faster "
              f"than PHCpack): {word[c['first_met']]}")
        print(f"  re-solve       {c['resolve_median_ms']:.0f} ms median, {c['resolve_speedup']:.0f} x faster than the "
              f"first solve (target < {TARGET_RESOLVE_MS:g} ms): {word[c['resolve_met']]}")
    return out


if __name__ == "__main__":
    main()
