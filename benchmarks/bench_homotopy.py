"""Benchmark: forward position by homotopy continuation (kinematics/homotopy/study.py) against
PHCpack's blackbox solver on the same polynomial system, measured in the same run.

    python benchmarks/bench_homotopy.py [--json] [--quick] [--certify-only]

Targets of the homotopy issue: every solution of the Stewart platform faster than PHCpack's
blackbox solver (goal: under 2 s), and a parameter-homotopy re-solve for new leg lengths under
50 ms (it reuses the cached generic solve, ``resolve_cached``), reported with
``resolve_speedup``, the first solve's time over the re-solve's median in the same run.
Cases: the ready-made stewart-6sps (a symmetric geometry: 28 generic solutions) and a random
general 6-6 platform (40).  ``phc`` is Debian's phcpack; without it that baseline is
skipped and said so.

Inverse position of one limb by homotopy (kinematics/homotopy/inverse.py, issue 27), reported
under ``ik``: ``ik_6r_first_s`` (a random general 6R: the generic solve, monodromy to the 16 of
the root count, then the pose; target < 2 s; numba compilation excluded by a warm-up on another
geometry), ``ik_6r_resolve_ms`` (median re-solve at new poses, the 16 cached paths; target
< 50 ms) and ``ik_puma_solutions`` (the PUMA 560: 8).

Certified solutions (kinematics/homotopy/certify.py, issue 27), reported under ``certify``:
``certify_overhead_fraction``, the largest over the cases of the median of the certificates'
time over the rest of the same solve (``sm.fk`` / ``sm.ik`` with ``all_solutions``, re-solves at
new actuator values or poses, the generic solve cached: the smallest solves, so the largest
fractions), target <= 0.25.  Cases: stewart-6sps forward (8 real solutions and 20 complex end
points certified) and the inverse position of the PUMA 560 (8) and of a random general 6R.
``certify_compiled`` (``--certify-only`` and the full run): the PUMA 560's certificates alone
(``certify_inverse`` on the 8 solutions of each pose), compiled float pass
(``compiled/kernels_certify.py``) against the Python reference (``backend.python_reference()``),
alternating in the same run: ``ms`` and ``ms_reference`` (medians per pose) and their ratio
``speedup``.
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
TARGET_IK_FIRST_S = 2.0
TARGET_IK_RESOLVE_MS = 50.0
TARGET_CERTIFY_FRACTION = 0.25


def _dh_arm(dh):
    """A serial arm of standard-DH R joints (as tests/test_ik_distinct.py) and its pose function."""
    from spatialmech.model.joints import R
    from spatialmech.model.mechanism import Limb, Mechanism, Pose

    def frames(theta):
        T = np.eye(4)
        out = [T]
        for (d, a, al), t in zip(dh, theta, strict=True):
            ct, st, ca, sa = np.cos(t), np.sin(t), np.cos(al), np.sin(al)
            T = T @ np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d],
                              [0, 0, 0, 1.0]])
            out.append(T)
        return out

    F = frames(np.zeros(len(dh)))
    mech = Mechanism("arm", (Limb("arm", tuple(R(f"J{i + 1}", F[i][:3, 3], F[i][:3, 2]) for i in range(len(dh)))),),
                     platform_point=F[-1][:3, 3])

    def pose(theta):
        return Pose.from_displacement(frames(theta)[-1] @ np.linalg.inv(F[-1]), F[-1][:3, 3])

    return mech, pose


def ik_case(resolves: int) -> dict:
    """The limb inverse position by homotopy: a random 6R and the PUMA 560."""
    from spatialmech.kinematics.homotopy import inverse as ikh
    from spatialmech.kinematics.position import inverse_position

    puma = [(0.0, 0.0, np.pi / 2), (0.0, 0.4318, 0.0), (0.15005, 0.0203, -np.pi / 2), (0.4318, 0.0, np.pi / 2),
            (0.0, 0.0, -np.pi / 2), (0.0, 0.0, 0.0)]
    rng = np.random.default_rng(0)
    warm = [(rng.uniform(-0.5, 0.5), rng.uniform(0.1, 0.6), rng.uniform(-np.pi, np.pi)) for _ in range(6)]
    m, pose = _dh_arm(warm)
    # numba compilation, not timed: at a random pose (the DH zero is a singular configuration of every
    # standard-DH arm: no regular real solution there, so the certificates' kernels would not be reached)
    inverse_position(m, pose(np.random.default_rng(1).uniform(-np.pi, np.pi, 6)), all_solutions=True)
    dh = [(rng.uniform(-0.5, 0.5), rng.uniform(0.1, 0.6), rng.uniform(-np.pi, np.pi)) for _ in range(6)]
    m, pose = _dh_arm(dh)
    ikh.clear_cache()
    t0 = time.perf_counter()
    res = inverse_position(m, pose(rng.uniform(-np.pi, np.pi, 6)), all_solutions=True, method="homotopy")
    first = time.perf_counter() - t0
    rep = res.search["limbs"][0]
    times = []
    for _ in range(resolves):
        p = pose(rng.uniform(-np.pi, np.pi, 6))
        t0 = time.perf_counter()
        inverse_position(m, p, all_solutions=True, method="homotopy")
        times.append(time.perf_counter() - t0)
    mp, posep = _dh_arm(puma)
    rp = inverse_position(mp, posep(np.array([0.3, -0.7, 0.5, 0.9, 0.6, -0.4])), all_solutions=True, method="homotopy")
    resolve_ms = float(np.median(times) * 1e3)
    return {"ik_6r_first_s": first, "ik_6r_resolve_ms": resolve_ms, "ik_6r_resolve_speedup": first * 1e3 / resolve_ms,
            "ik_6r_paths": rep["n_paths"], "ik_6r_real": rep["n_real"], "ik_6r_complete": rep["complete"],
            "ik_puma_solutions": len(rp.limbs[0].solutions), "ik_puma_complete": rp.search["limbs"][0]["complete"],
            "ik_first_met": first < TARGET_IK_FIRST_S, "ik_resolve_met": resolve_ms < TARGET_IK_RESOLVE_MS,
            "ik_puma_met": len(rp.limbs[0].solutions) == 8}


def certify_case(resolves: int, quick: bool = False) -> dict:
    """The certificates' share of a solve: ``certify_elapsed_s`` (reported by the solve) over the
    rest of the same call, median over re-solves, per case (``quick``: without the general 6R)."""
    import spatialmech as sm

    rng = np.random.default_rng(11)
    out: dict = {"cases": {}}
    mech = catalog.build("stewart-6sps")
    sm.fk(mech, np.full(6, 1.2), all_solutions=True)  # the generic solve, cached
    fr, ok = [], True
    for _ in range(resolves):
        t0 = time.perf_counter()
        d = sm.fk(mech, 1.2 * (1 + 0.02 * rng.standard_normal(6)), all_solutions=True).answer.detail.search
        total = time.perf_counter() - t0
        fr.append(d["certify_elapsed_s"] / (total - d["certify_elapsed_s"]))
        ok &= d["n_certified"] == d["distinct"] and d["n_certified_complex"] > 0
    out["cases"]["stewart-6sps fk"] = {"fraction": float(np.median(fr)), "all_certified": bool(ok)}
    puma = [(0.0, 0.0, np.pi / 2), (0.0, 0.4318, 0.0), (0.15005, 0.0203, -np.pi / 2), (0.4318, 0.0, np.pi / 2),
            (0.0, 0.0, -np.pi / 2), (0.0, 0.0, 0.0)]
    general = [(rng.uniform(-0.5, 0.5), rng.uniform(0.1, 0.6), rng.uniform(-np.pi, np.pi)) for _ in range(6)]
    for name, dh in (("PUMA 560 ik", puma), ("general 6R ik", general))[: 1 if quick else 2]:
        m, pose = _dh_arm(dh)
        sm.ik(m, pose(np.zeros(6)), all_solutions=True)  # the generic solve, cached
        fr, ok = [], True
        for _ in range(resolves):
            p = pose(rng.uniform(-np.pi, np.pi, 6))
            t0 = time.perf_counter()
            rep = sm.ik(m, p, all_solutions=True).result.search["limbs"][0]
            total = time.perf_counter() - t0
            fr.append(rep["certify_elapsed_s"] / (total - rep["certify_elapsed_s"]))
            ok &= rep["n_certified"] == rep["n_real"]
        out["cases"][name] = {"fraction": float(np.median(fr)), "all_certified": bool(ok)}
    frac = max(c["fraction"] for c in out["cases"].values())
    out["certify_overhead_fraction"] = frac
    out["certify_met"] = frac <= TARGET_CERTIFY_FRACTION and all(c["all_certified"] for c in out["cases"].values())
    return out


def certify_compiled_case(poses: int) -> dict:
    """The PUMA 560's certificates alone at ``poses`` random poses (8 solutions each):
    ``certify_inverse`` with the compiled float pass and on the Python reference, alternating
    pose by pose; medians in ms per pose and their ratio."""
    import spatialmech as sm
    from spatialmech.kinematics import backend
    from spatialmech.kinematics.homotopy import certify as C
    from spatialmech.kinematics.homotopy import inverse as ikh

    puma = [(0.0, 0.0, np.pi / 2), (0.0, 0.4318, 0.0), (0.15005, 0.0203, -np.pi / 2), (0.4318, 0.0, np.pi / 2),
            (0.0, 0.0, -np.pi / 2), (0.0, 0.0, 0.0)]
    m, pose = _dh_arm(puma)
    sysm = ikh.limb_ik_system(m, 0)
    rng = np.random.default_rng(12)
    fast, ref, same = [], [], True
    for _ in range(poses):
        p = pose(rng.uniform(-np.pi, np.pi, 6))
        qs = [np.asarray(q) for q in sm.ik(m, p, all_solutions=True, certify=False).result.limbs[0].solutions]
        D = p.displacement(m.platform_point)
        C.certify_inverse(sysm, D, qs)  # the pose's ball constants and caches, not timed
        t0 = time.perf_counter()
        a = C.certify_inverse(sysm, D, qs)
        t1 = time.perf_counter()
        with backend.python_reference():
            b = C.certify_inverse(sysm, D, qs)
        t2 = time.perf_counter()
        fast.append(t1 - t0)
        ref.append(t2 - t1)
        same &= a == b
    ms, ms_ref = float(np.median(fast) * 1e3), float(np.median(ref) * 1e3)
    return {"poses": poses, "ms": ms, "ms_reference": ms_ref, "speedup": ms_ref / ms, "same_certificates": bool(same)}


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


def certify_main(as_json: bool) -> dict:
    """``--certify-only``: :func:`certify_case` alone (15 re-solves per case)."""
    cert = certify_case(15)
    cert["certify_compiled"] = certify_compiled_case(15)
    out = {"certify": cert, "certify_overhead_fraction": cert["certify_overhead_fraction"],
           "targets": {"certify_overhead_fraction": TARGET_CERTIFY_FRACTION}}
    if as_json:
        print(json.dumps(out, indent=2))
        return out
    print("certificates   share of a re-solve (median): " + ", ".join(
        f"{k} {v['fraction']:.0%}{'' if v['all_certified'] else ' (NOT all certified)'}" for k, v in cert["cases"].items())
          + f" (target <= {TARGET_CERTIFY_FRACTION:.0%}): {'met' if cert['certify_met'] else 'NOT met'}")
    print(_compiled_line(cert["certify_compiled"]))
    return out


def _compiled_line(c: dict) -> str:
    return (f"certificates   PUMA 560 alone: {c['ms']:.2f} ms per pose compiled, {c['ms_reference']:.2f} ms on the Python "
            f"reference ({c['speedup']:.1f} x, same certificates: {c['same_certificates']})")


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--quick", action="store_true", help="one case, two re-solves, no PHCpack (smoke test)")
    ap.add_argument("--certify-only", action="store_true", help="the certificates' share of a re-solve only")
    args = ap.parse_args(argv)
    if args.certify_only:
        return certify_main(args.json)
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
    ik = ik_case(3 if args.quick else 20)
    cert = certify_case(3 if args.quick else 15, quick=args.quick)
    cert["certify_compiled"] = certify_compiled_case(2 if args.quick else 15)
    out = {"cases": cases, "targets": {"first_solve_s": TARGET_FIRST_S, "resolve_ms": TARGET_RESOLVE_MS,
                                       "ik_6r_first_s": TARGET_IK_FIRST_S, "ik_6r_resolve_ms": TARGET_IK_RESOLVE_MS,
                                       "ik_puma_solutions": 8, "certify_overhead_fraction": TARGET_CERTIFY_FRACTION},
           "certify": cert, "certify_overhead_fraction": cert["certify_overhead_fraction"],
           "phc": shutil.which("phc") is not None, "ik": ik, **{k: ik[k] for k in
                                                                ("ik_6r_first_s", "ik_6r_resolve_ms", "ik_puma_solutions")}}
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
    print(f"limb IK 6R     {ik['ik_6r_paths']} paths, {ik['ik_6r_real']} real, complete {ik['ik_6r_complete']}")
    print(f"  first solve    {ik['ik_6r_first_s']:.2f} s (target < {TARGET_IK_FIRST_S:g} s): {word[ik['ik_first_met']]}")
    print(f"  re-solve       {ik['ik_6r_resolve_ms']:.0f} ms median, {ik['ik_6r_resolve_speedup']:.0f} x faster than the "
          f"first solve (target < {TARGET_IK_RESOLVE_MS:g} ms): {word[ik['ik_resolve_met']]}")
    print(f"limb IK PUMA   {ik['ik_puma_solutions']} solutions (target 8), complete {ik['ik_puma_complete']}: "
          f"{word[ik['ik_puma_met']]}")
    print("certificates   share of a re-solve (median): " + ", ".join(
        f"{k} {v['fraction']:.0%}{'' if v['all_certified'] else ' (NOT all certified)'}" for k, v in cert["cases"].items())
          + f" (target <= {TARGET_CERTIFY_FRACTION:.0%}): {word[cert['certify_met']]}")
    print(_compiled_line(cert["certify_compiled"]))
    return out


if __name__ == "__main__":
    main()
