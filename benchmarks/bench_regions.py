"""Benchmark: solution region 1 cells per second, vectorised vs a naive per-cell loop.

Run: ``python benchmarks/bench_regions.py [--samples N] [--naive-cells M]``.  Both rates are
measured in the same run on the paper D task (``rccc-four-positions``); the naive loop calls
the same classifier once per cell, on a subset of ``M`` cells.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from spatialmech.synthesis.burmester import burmester_curves
from spatialmech.synthesis.regions import classify_spherical_4r, solution_region_1
from spatialmech.synthesis.tasks import get_task


def run(samples: int = 360, naive_cells: int = 2000, seed: int = 0) -> dict:
    task = get_task("rccc-four-positions")
    curves = burmester_curves(task, samples=samples)
    t0 = time.perf_counter()
    region = solution_region_1(task, curves)
    t_vec = time.perf_counter() - t0
    rng = np.random.default_rng(seed)
    n = len(curves.t)
    cells = rng.integers(0, n, size=(naive_cells, 2))
    t0 = time.perf_counter()
    agree = 0
    for i, k in cells:
        T, D = classify_spherical_4r(task.C, curves.u[i], curves.v[i], curves.u[k], curves.v[k])
        agree += int(region.type[i, k] == T and region.defects[i, k] == D)
    t_naive = time.perf_counter() - t0
    return {
        "cells": region.n_cells,
        "vectorised_seconds": t_vec,
        "vectorised_cells_per_second": region.n_cells / t_vec,
        "naive_cells": int(naive_cells),
        "naive_seconds": t_naive,
        "naive_cells_per_second": naive_cells / t_naive,
        "speedup": (region.n_cells / t_vec) / (naive_cells / t_naive),
        "naive_agrees": agree == naive_cells,
    }


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--samples", type=int, default=360, help="samples per curve branch")
    ap.add_argument("--naive-cells", type=int, default=2000, help="cells classified one by one")
    a = ap.parse_args(argv)
    print(json.dumps(run(a.samples, a.naive_cells), indent=2))


if __name__ == "__main__":
    main()
