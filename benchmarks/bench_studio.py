"""Benchmark: how fast the design studio answers a drag, over its HTTP API (FastAPI's
TestClient, in process: the JSON encoding and the app are included, the network is not).

    python benchmarks/bench_studio.py [--json] [--quick]

Per model, a drag is a sequence of ``POST /api/drive`` with small actuator increments (the page
sends the next slider value when the previous answer has arrived): 1 degree for the 5-CS
linkages' crank (P1 towards P7), 2 mm on every leg for the Stewart platform, 1 mm for the
4-SPS/CU.  A pose drag is a sequence of ``POST /api/pose`` moving one task coordinate of the
output link (inverse position along the branch): the Stewart platform's z by 2 mm, the
4-SPS/CU's a3 and the 5-CS linkage 3's y by small steps.  Reported: median and 95th
percentile of the answer time, and of the time the solver took inside it (``elapsed_s``).
The target of issue 16 is under 50 ms per update.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from fastapi.testclient import TestClient

import spatialmech as sm

#: (model, increments per drag update, number of updates)
CASES = [
    ("five-cs-3", -1.0, 60),
    ("stewart-6sps", 0.002, 40),
    ("four-sps-cu", 0.001, 40),
    ("rssr", 2.0, 60),
]
#: (model, task coordinate, increment per pose update (length unit or degrees), number of updates)
POSE_CASES = [
    ("stewart-6sps", "z", 0.002, 40),
    ("four-sps-cu", "a3", 0.5, 40),
    ("five-cs-3", "y", 0.05, 40),
]


def run(model: str, step: float, n: int) -> dict:
    client = TestClient(sm.studio_app(model))
    st = client.get("/api/state").json()["state"]
    vals = np.array([st["actuators_deg"].get(d, st["actuators_len"].get(d)) for d in st["drivers"]], dtype=float)
    client.post("/api/drive", json={"actuators": (vals + step).tolist()})  # compile / warm up
    vals = vals + step
    targets = (vals + step * (k + 1) for k in range(n))
    return timed_updates(model, n, lambda: client.post("/api/drive", json={"actuators": next(targets).tolist()}))


def timed_updates(label: str, n: int, post) -> dict:
    """``n`` updates ``post()`` (an HTTP answer), stopping at the first that does not reach its
    target: the answer's wall time and the solver's own time, median and 95th percentile."""
    wall, inner, statuses = [], [], []
    for _ in range(n):
        t = time.perf_counter()
        d = post().json()
        wall.append(time.perf_counter() - t)
        inner.append(d["elapsed_s"])
        statuses.append(d["status"])
        if d["status"] != "reached":
            break
    ms = lambda v, q: round(1000 * float(np.percentile(v, q)), 1)  # noqa: E731
    return {"model": label, "updates": len(wall), "last_status": statuses[-1],
            "answer_median_ms": ms(wall, 50), "answer_p95_ms": ms(wall, 95),
            "solver_median_ms": ms(inner, 50), "solver_p95_ms": ms(inner, 95)}


def run_pose(model: str, coord: str, step: float, n: int) -> dict:
    client = TestClient(sm.studio_app(model))
    key = "task_deg" if coord.startswith("a") else "task_len"
    body = {key: {coord: step}, "relative": True}
    client.post("/api/pose", json=body)  # compile / warm up
    return timed_updates(f"{model} pose {coord}", n, lambda: client.post("/api/pose", json=body))


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--quick", action="store_true", help="10 updates per model")
    args = ap.parse_args(argv)
    rows = [run(m, s, 10 if args.quick else n) for m, s, n in CASES]
    rows += [run_pose(m, c, s, 10 if args.quick else n) for m, c, s, n in POSE_CASES]
    out = {"rows": rows}
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        for r in rows:
            print(f"{r['model']:<22} {r['updates']:>3} updates ({r['last_status']}): answer median {r['answer_median_ms']} ms, "
                  f"p95 {r['answer_p95_ms']} ms; solver median {r['solver_median_ms']} ms, p95 {r['solver_p95_ms']} ms")
    return out


if __name__ == "__main__":
    main()
