"""Grassmann line geometry: synthetic sets for every case (invariant under rigid displacements
and changes of unit), and the singular cases of paper B (seed 002, section 5.2)."""

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spatialmech.catalog.papers import four_sps_cu, four_sps_cu_points
from spatialmech.geometry import screws as sc
from spatialmech.geometry.line_geometry import classify_lines, pair_relation
from spatialmech.geometry.rotations import euler_matrix
from spatialmech.kinematics.closure import Configuration, joint_points
from spatialmech.kinematics.backend import correct
from spatialmech.model.mechanism import Pose

from .conftest import random_transform

seeds = st.integers(0, 2**32 - 1)
L0 = 1.0  # length scale of the synthetic sets (m)


# ---------------------------------------------------------------- helpers
def line(d, p):
    d = np.asarray(d, float)
    return sc.plucker_line(d / np.linalg.norm(d), p)


def through(a, b):
    return line(np.asarray(b, float) - a, a)


def unit(rng):
    v = rng.standard_normal(3)
    return v / np.linalg.norm(v)


def lines_in_system(system, n, rng):
    """``n`` random lines inside the span of ``system`` (screws): on random pencils of the
    system, solve the Klein quadric K(u + t v) = 0 for t."""
    B = sc.basis(system)
    out = []
    while len(out) < n:
        u, v = rng.standard_normal(len(B)) @ B, rng.standard_normal(len(B)) @ B
        def k(x, y):
            return x[:3] @ y[3:] + y[:3] @ x[3:]
        a, b, c = k(v, v) / 2, k(u, v), k(u, u) / 2
        disc = b * b - 4 * a * c
        if disc < 0 or abs(a) < 1e-9:
            continue
        x = u + (-b + np.sqrt(disc)) / (2 * a) * v
        s = np.linalg.norm(x[:3])
        if s < 1e-6:
            continue
        x = x / s
        x[3:] -= x[:3] * (x[:3] @ x[3:])  # round-off
        out.append(x)
    return np.array(out)


def same_line(a, b, tol=1e-7):
    return np.allclose(a, b, atol=tol) or np.allclose(a, -b, atol=tol)


def moved(T, lines):
    return sc.transform_screws(T, lines)


def move_point(T, p):
    return T[:3, :3] @ p + T[:3, 3]


def on_line(p, l, tol=1e-8):
    return np.linalg.norm(np.cross(p - sc.line_point(l), l[:3])) < tol


# ---------------------------------------------------------------- synthetic cases
@settings(max_examples=15, deadline=None)
@given(seeds)
def test_parallel_lines_rank_3_with_their_direction(seed):
    rng = np.random.default_rng(seed)
    T = random_transform(seed)
    d = unit(rng)
    L = np.array([line(d, rng.uniform(-1, 1, 3)) for _ in range(4)])
    for lines, dd in ((L, d), (moved(T, L), T[:3, :3] @ d)):
        g = classify_lines(lines, length_scale=L0)
        assert (g.rank, g.case, g.variety) == (3, "parallel", "bundle")
        assert abs(abs(g.witnesses["direction"] @ dd) - 1) < 1e-12
        assert g.groups["parallel"][0]["lines"] == [0, 1, 2, 3]


@settings(max_examples=15, deadline=None)
@given(seeds)
def test_concurrent_lines_rank_3_with_their_point(seed):
    rng = np.random.default_rng(seed)
    T = random_transform(seed)
    p = rng.uniform(-2, 2, 3)
    L = np.array([line(unit(rng), p) for _ in range(5)])
    for lines, pp in ((L, p), (moved(T, L), move_point(T, p))):
        g = classify_lines(lines, length_scale=L0)
        assert (g.rank, g.case) == (3, "concurrent")
        assert np.allclose(g.witnesses["point"], pp, atol=1e-9)
        assert g.groups["concurrent"][0]["lines"] == [0, 1, 2, 3, 4]


@settings(max_examples=15, deadline=None)
@given(seeds)
def test_coplanar_lines_rank_3_with_their_plane(seed):
    rng = np.random.default_rng(seed)
    T = random_transform(seed)
    n = unit(rng)
    e1 = unit(rng)
    e1 -= n * (n @ e1)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    q = rng.uniform(-1, 1, 3)
    def pts():
        return q + rng.uniform(-1, 1) * e1 + rng.uniform(-1, 1) * e2
    L = np.array([through(pts(), pts()) for _ in range(4)])
    for lines, nn, qq in ((L, n, q), (moved(T, L), T[:3, :3] @ n, move_point(T, q))):
        g = classify_lines(lines, length_scale=L0)
        assert (g.rank, g.case) == (3, "coplanar")
        pl = g.witnesses["plane"]
        assert abs(abs(pl["normal"] @ nn) - 1) < 1e-9
        assert abs(pl["normal"] @ qq - pl["offset"]) < 1e-9


@settings(max_examples=10, deadline=None)
@given(seeds)
def test_rank_2_and_rank_1_sets(seed):
    rng = np.random.default_rng(seed)
    T = random_transform(seed)
    p, n = rng.uniform(-1, 1, 3), unit(rng)
    def inplane():
        return np.cross(n, unit(rng))
    pencil = np.array([line(inplane(), p) for _ in range(3)])
    d = inplane()
    par_pencil = np.array([line(d, p + k * np.cross(n, d)) for k in (0.0, 0.3, -0.7)])
    skew = np.array([line([1, 0, 0], [0, 0, 0]), line([0, 1, 0], [0, 0, 1])])
    single = np.array([line(d, p), line(-d, p + 2 * d)])
    for lines, case, r in ((pencil, "planar-pencil", 2), (par_pencil, "parallel-planar-pencil", 2),
                           (skew, "two-skew-lines", 2), (single, "single-line", 1)):
        for L in (lines, moved(T, lines)):
            g = classify_lines(L, length_scale=L0)
            assert (g.rank, g.case) == (r, case)
    g = classify_lines(moved(T, pencil), length_scale=L0)
    assert np.allclose(g.witnesses["point"], move_point(T, p), atol=1e-9)
    assert abs(abs(g.witnesses["plane"]["normal"] @ (T[:3, :3] @ n)) - 1) < 1e-9


@settings(max_examples=15, deadline=None)
@given(seeds)
def test_two_planar_pencils_sharing_a_line(seed):
    """Lines {0, 1} through P in plane pi1, lines {2, 3} through Q in plane pi2, both planes
    containing the line PQ: rank 3, the common line is PQ and the pencils are recovered."""
    rng = np.random.default_rng(seed)
    P, Q = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
    u = (Q - P) / np.linalg.norm(Q - P)
    w1, w2 = unit(rng), unit(rng)
    def in1():
        return np.cross(u, w1) * rng.uniform(0.5, 1) + u * rng.uniform(-1, 1)
    def in2():
        return np.cross(u, w2) * rng.uniform(0.5, 1) + u * rng.uniform(-1, 1)
    L = np.array([line(in1(), P), line(in1(), P), line(in2(), Q), line(in2(), Q)])
    T = random_transform(seed)
    for lines, PP, QQ in ((L, P, Q), (moved(T, L), move_point(T, P), move_point(T, Q))):
        g = classify_lines(lines, length_scale=L0)
        assert (g.rank, g.case) == (3, "two-pencils-sharing-a-line")
        assert same_line(g.witnesses["common_line"], through(PP, QQ), 1e-8)
        pens = g.witnesses["pencils"]
        assert [p["lines"] for p in pens] == [[0, 1], [2, 3]]
        assert np.allclose(pens[0]["point"], PP, atol=1e-8) and np.allclose(pens[1]["point"], QQ, atol=1e-8)


def test_two_parallel_pencils_in_parallel_planes_share_the_line_at_infinity():
    """Lines {0, 1} parallel to x in z = 0, lines {2, 3} parallel to y in z = 1: rank 3, two
    pencils whose common line is the line at infinity of the planes normal to z."""
    L = np.array([line([1, 0, 0], [0, 0, 0]), line([1, 0, 0], [0, 1, 0]),
                  line([0, 1, 0], [0, 0, 1]), line([0, 1, 0], [2, 0, 1])])
    g = classify_lines(L, length_scale=L0)
    assert (g.rank, g.case) == (3, "two-pencils-sharing-a-line")
    assert np.allclose(g.witnesses["common_line_at_infinity_normal"], [0, 0, 1])
    assert [p["lines"] for p in g.witnesses["pencils"]] == [[0, 1], [2, 3]]
    assert [p["plane"]["offset"] for p in g.witnesses["pencils"]] == [0.0, 1.0]


def test_two_pencils_one_of_parallel_lines():
    """Lines {0, 1} parallel to x in y = 0 (centre at infinity), lines {2, 3} through
    Q = (0, 0, 1) in z = 1: they share the x-parallel line through Q."""
    Q = np.array([0, 0, 1.0])
    L = np.array([line([1, 0, 0], [0, 0, 0]), line([1, 0, 0], [0, 0, 2]),
                  line([0, 1, 0], Q), line([1, 1, 0], Q)])
    g = classify_lines(L, length_scale=L0)
    assert (g.rank, g.case) == (3, "two-pencils-sharing-a-line")
    assert same_line(g.witnesses["common_line"], line([1, 0, 0], Q))
    p0, p1 = g.witnesses["pencils"]
    assert np.allclose(np.abs(p0["direction"]), [1, 0, 0]) and np.allclose(p1["point"], Q)
    assert "point at infinity along (1, 0, 0)" in g.description


@settings(max_examples=15, deadline=None)
@given(seeds)
def test_regulus_of_a_hyperboloid(seed):
    """Four lines of one ruling of x^2/a^2 + y^2/b^2 - z^2/c^2 = 1: rank 3, regulus; the three
    transversal witnesses are lines that meet every input line (other ruling)."""
    rng = np.random.default_rng(seed)
    a, b, c = rng.uniform(0.5, 2, 3)
    ts = rng.uniform(0, 2 * np.pi, 4)
    L = np.array([line([-a * np.sin(t), b * np.cos(t), c], [a * np.cos(t), b * np.sin(t), 0]) for t in ts])
    T = random_transform(seed)
    for lines in (L, moved(T, L)):
        g = classify_lines(lines, length_scale=L0)
        assert (g.rank, g.case) == (3, "regulus")
        for tr in g.witnesses["transversals"]:
            assert abs(np.linalg.norm(tr[:3]) - 1) < 1e-9 and abs(tr[:3] @ tr[3:]) < 1e-9
            assert np.allclose(sc.reciprocal_product(tr, lines), 0, atol=1e-9)
        tr = g.witnesses["transversals"]
        assert sc.rank(tr) == 3


@pytest.mark.slow
@settings(max_examples=10, deadline=None)
@given(seeds)
def test_congruences(seed):
    """Rank 4: lines meeting two skew lines (hyperbolic, both directrices recovered); lines
    through a point or in a plane through it (degenerate, point and plane recovered); lines
    reciprocal to a line and a screw of pitch h reciprocal to it (parabolic); lines reciprocal
    to two screws of equal pitch on perpendicular intersecting axes (elliptic)."""
    rng = np.random.default_rng(seed)
    T = random_transform(seed)
    D1, D2 = line(unit(rng), rng.uniform(-1, 1, 3)), line(unit(rng), rng.uniform(-1, 1, 3))
    hyper = np.array([through(sc.line_point(D1) + rng.uniform(-2, 2) * D1[:3],
                              sc.line_point(D2) + rng.uniform(-2, 2) * D2[:3]) for _ in range(5)])
    P, n = rng.uniform(-1, 1, 3), unit(rng)
    degen = np.array([line(unit(rng), P), line(unit(rng), P),
                      through(P + np.cross(n, unit(rng)), P + np.cross(n, unit(rng))),
                      through(P + np.cross(n, unit(rng)), P + np.cross(n, unit(rng)))])
    h = rng.uniform(0.2, 1.0)
    z, x = np.array([0, 0, 1.0]), np.array([1.0, 0, 0])
    parab = lines_in_system(sc.reciprocal_basis(np.array([np.r_[z, 0, 0, 0], np.r_[x, h * x]])), 5, rng)
    ellip = lines_in_system(sc.reciprocal_basis(np.array([np.r_[z, h * z], np.r_[x, h * x]])), 5, rng)
    for L, case in ((hyper, "hyperbolic-congruence"), (degen, "degenerate-congruence"),
                    (parab, "parabolic-congruence"), (ellip, "elliptic-congruence")):
        for lines in (L, moved(T, L)):
            g = classify_lines(lines, length_scale=L0)
            assert (g.rank, g.case, g.variety) == (4, case, "congruence"), case
    g = classify_lines(moved(T, hyper), length_scale=L0)
    got = [d["line"] for d in g.witnesses["directrices"]]
    want = moved(T, np.array([D1, D2]))
    assert (same_line(got[0], want[0], 1e-7) and same_line(got[1], want[1], 1e-7)) or (
        same_line(got[0], want[1], 1e-7) and same_line(got[1], want[0], 1e-7))
    g = classify_lines(moved(T, degen), length_scale=L0)
    assert np.allclose(g.witnesses["point"], move_point(T, P), atol=1e-8)
    assert abs(abs(g.witnesses["plane"]["normal"] @ (T[:3, :3] @ n)) - 1) < 1e-8
    g = classify_lines(parab, length_scale=L0)
    assert same_line(g.witnesses["directrices"][0]["line"], np.r_[z, 0, 0, 0], 1e-7)


@settings(max_examples=10, deadline=None)
@given(seeds)
def test_complexes_and_general_sets(seed):
    """Rank 5: five lines meeting an axis (special complex, axis recovered), five lines
    perpendicular to a direction (special complex at infinity), five lines reciprocal to a
    screw of pitch h (general complex: axis and pitch recovered); six random lines: general."""
    rng = np.random.default_rng(seed)
    T = random_transform(seed)
    A = line(unit(rng), rng.uniform(-1, 1, 3))
    special = np.array([line(unit(rng), sc.line_point(A) + rng.uniform(-2, 2) * A[:3]) for _ in range(5)])
    v = unit(rng)
    perp = np.array([line(np.cross(v, unit(rng)), rng.uniform(-1, 1, 3)) for _ in range(5)])
    h = rng.uniform(0.1, 0.5) * rng.choice([-1, 1])
    W = A.copy()
    W[3:] += h * A[:3]
    general_complex = lines_in_system(sc.reciprocal_basis(W[None, :]), 5, rng)
    g = classify_lines(moved(T, special), length_scale=L0)
    assert (g.rank, g.case) == (5, "special-complex")
    assert same_line(g.witnesses["axis"], moved(T, A), 1e-7)
    g = classify_lines(moved(T, perp), length_scale=L0)
    assert (g.rank, g.case) == (5, "special-complex-at-infinity")
    assert abs(abs(g.witnesses["normal"] @ (T[:3, :3] @ v)) - 1) < 1e-9
    g = classify_lines(moved(T, general_complex), length_scale=L0)
    assert (g.rank, g.case) == (5, "general-complex")
    assert abs(g.witnesses["pitch"] - h) < 1e-8
    assert same_line(g.witnesses["axis"], moved(T, A), 1e-7)
    g = classify_lines(np.array([line(unit(rng), rng.uniform(-1, 1, 3)) for _ in range(6)]), length_scale=L0)
    assert (g.rank, g.case, g.singular) == (6, "general", False)


@settings(max_examples=10, deadline=None)
@given(seeds, st.sampled_from([1e-3, 1.0, 1e3]))
def test_classification_does_not_depend_on_the_unit_of_length(seed, k):
    """Scaling every length by k (moments x k) with length_scale x k gives the same case and
    witnesses scaled by k (a mm model classified like an m model)."""
    rng = np.random.default_rng(seed)
    P, Q = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
    u = (Q - P) / np.linalg.norm(Q - P)
    w, w2 = unit(rng), unit(rng)
    L = np.array([line(np.cross(u, w) + u * 0.3, P), line(np.cross(u, w) - u, P),
                  line(np.cross(u, w2) + u, Q), line(np.cross(u, w2) - u * 0.2, Q)])
    Lk = L.copy()
    Lk[:, 3:] *= k
    g, gk = classify_lines(L, length_scale=1.0), classify_lines(Lk, length_scale=k)
    assert g.case == gk.case == "two-pencils-sharing-a-line"
    assert np.allclose(gk.witnesses["pencils"][0]["point"], k * g.witnesses["pencils"][0]["point"], atol=1e-8 * k)


def test_pair_relations():
    a = line([1, 0, 0], [0, 0, 0])
    assert pair_relation(a, line([0, 1, 0], [2, 0, 0]))["relation"] == "intersect"
    assert np.allclose(pair_relation(a, line([0, 1, 0], [2, 0, 0]))["point"], [2, 0, 0])
    r = pair_relation(a, line([-1, 0, 0], [0, 3, 0]))
    assert r["relation"] == "parallel" and abs(r["distance"] - 3) < 1e-12
    r = pair_relation(a, line([0, 1, 0], [0, 0, 2]))
    assert r["relation"] == "skew" and abs(r["distance"] - 2) < 1e-12 and abs(r["angle"] - np.pi / 2) < 1e-12
    assert pair_relation(a, line([-1, 0, 0], [5, 0, 0]))["relation"] == "coincide"


def test_circuits_are_minimal_dependent_subsets():
    """Three concurrent coplanar lines (a planar pencil) plus three generic lines: the only
    circuit is the pencil {0, 1, 2} (rank 2), although the whole set has rank 5."""
    rng = np.random.default_rng(0)
    p = np.array([0.1, 0.2, 0.3])
    L = np.array([line([1, 0, 0], p), line([0, 1, 0], p), line([1, 1, 0], p)]
                 + [line(unit(rng), rng.uniform(-1, 1, 3)) for _ in range(3)])
    g = classify_lines(L, length_scale=L0)
    assert g.rank == 5 and g.singular
    assert [c.indices for c in g.circuits] == [(0, 1, 2)]
    assert g.circuits[0].case == "planar-pencil"
    assert np.allclose(g.circuits[0].witnesses["point"], p)


# ---------------------------------------------------------------- paper B (seed 002, section 5.2)
def paper_b_lines(a, b, z, alpha=0.0, beta=0.0, gamma=0.0):
    """Four leg force lines B_i -> T A_i + (0, 0, z), T = Rz(gamma) Ry(beta) Rx(alpha) ('ZYX'),
    and the two CU constraint forces along X and Y through the U centre (0, 0, z)."""
    A, B = four_sps_cu_points(a, b)
    T = euler_matrix("ZYX", [gamma, beta, alpha])
    U = np.array([0.0, 0.0, z])
    legs = [through(B[i], T @ A[i] + U) for i in range(4)]
    return np.array([*legs, line([1, 0, 0], U), line([0, 1, 0], U)])


def test_paper_b_lines_agree_with_the_mechanism_model():
    """The lines above are the legs of catalog.papers.four_sps_cu at that pose: the engine's
    inverse position (platform held) puts the joint points B_i, A_i on them."""
    a, b, z0 = 0.1, 0.2, 0.2
    mech = four_sps_cu(a=a, b=b, z0=z0)
    z, al, be, ga = 0.23, 0.1, -0.05, 0.3
    D = Pose.from_euler("ZYX", [ga, be, al], [0, 0, z]).displacement(mech.platform_point)
    res = correct(mech, Configuration(np.zeros(len(mech.freedom_refs)), D), fix_platform=True)
    assert res.converged
    pts = joint_points(mech, res.config)
    L = paper_b_lines(a, b, z, al, be, ga)
    for i in range(4):
        assert on_line(pts[i][0], L[i]) and on_line(pts[i][-1], L[i])
    assert on_line(pts[4][-1], L[4]) and on_line(pts[4][-1], L[5])  # U centre


def test_paper_b_generic_pose_is_not_singular():
    """Section 5.1 eq 15: rank 6 at a generic pose (a = 0.1, b = 0.2, z = 0.2)."""
    g = classify_lines(paper_b_lines(0.1, 0.2, 0.2, 0.1, 0.05, 0.3), length_scale=0.2)
    assert (g.rank, g.case) == (6, "general") and not g.circuits


def test_paper_b_case_a_parallel_legs_need_a_equal_b():
    """Fig 3a: the four leg lines parallel -> rank(S) < 6.  Reproduces with a = b at
    alpha = beta = gamma = 0 (the legs are vertical): the circuit is the four legs, parallel
    to Z; the six lines form a special complex whose axis is the Z axis.  With a != b the same
    pose gives concurrent legs instead (case b)."""
    g = classify_lines(paper_b_lines(0.2, 0.2, 0.2), length_scale=0.2)
    assert g.rank == 5 and g.case == "special-complex"
    assert same_line(g.witnesses["axis"], line([0, 0, 1], [0, 0, 0]))
    c = g.find_circuit("parallel")
    assert c is not None and c.indices == (0, 1, 2, 3) and c.rank == 3
    assert np.allclose(np.abs(c.witnesses["direction"]), [0, 0, 1])
    assert classify_lines(paper_b_lines(0.1, 0.2, 0.2), length_scale=0.2).find_circuit("parallel") is None


@pytest.mark.parametrize("a, b, z", [(0.1, 0.2, 0.2), (0.1, 0.2, 0.12), (0.15, 0.1, 0.3)])
def test_paper_b_case_b_concurrent_legs_at_alpha_beta_gamma_zero(a, b, z):
    """Fig 3b: the four leg lines through one point -> rank(S) < 6.  With a != b at
    alpha = beta = gamma = 0 they meet on the Z axis at z b / (b - a) (tolerance 1e-12 m)."""
    g = classify_lines(paper_b_lines(a, b, z), length_scale=b)
    assert g.rank == 5
    c = g.find_circuit("concurrent")
    assert c is not None and c.indices == (0, 1, 2, 3)
    assert np.allclose(c.witnesses["point"], [0, 0, z * b / (b - a)], atol=1e-12)


@pytest.mark.parametrize("gamma", [0.3, -1.0, 2.0])
def test_paper_b_alpha_beta_zero_with_gamma_gives_a_regulus_not_a_common_point(gamma):
    """conventions.md: every alpha = beta = 0 pose is singular.  For gamma != 0 (a != b) the
    legs do NOT meet on the Z axis: they are four lines of one ruling of a hyperboloid of
    revolution about Z (a regulus, rank 3), obtained from each other by 90-degree turns about Z.
    The singularity is real (rank 5) but it is not the paper's case (b)."""
    g = classify_lines(paper_b_lines(0.1, 0.2, 0.2, 0.0, 0.0, gamma), length_scale=0.2)
    assert g.rank == 5
    c = g.circuits[0]
    assert c.indices == (0, 1, 2, 3) and c.case == "regulus"
    assert not g.groups["concurrent"]


def _case_c_lines(P14, P23, u=(0.0, 0.0, 0.2)):
    """Leg lines of a paper-B geometry whose platform points are chosen on the lines
    B1-P14, B2-P23, B3-P23, B4-P14 (paper B's base square, b = 0.2; the platform is no longer a
    square), plus the CU forces through the U centre ``u``."""
    _, B = four_sps_cu_points(0.1, 0.2)
    u = np.asarray(u, float)
    legs = [through(B[0], P14), through(B[1], P23), through(B[2], P23), through(B[3], P14)]
    return np.array([*legs, line([1, 0, 0], u), line([0, 1, 0], u)])


def test_paper_b_case_c_true_condition_drops_the_rank():
    """Fig 3c, corrected (conventions.md): legs 1, 4 meet at P14, legs 2, 3 at P23, and both
    points lie on the intersection line of the pencils' own planes A1A4B4B1 and A2A3B3B2.
    Those planes contain the base edges B1B4 and B2B3 (along X), so the line is parallel to X:
    P14 = (0.05, 0.03, 0.45), P23 = (-0.12, 0.03, 0.45).  The legs form two planar pencils
    sharing that line: rank 3, and the six lines have rank 5 (singular).

    With paper B's square platform no such pose was found (multi-start least squares over
    (z, alpha, beta, gamma) and a/b): the case needs another geometry, built here."""
    P14, P23 = np.array([0.05, 0.03, 0.45]), np.array([-0.12, 0.03, 0.45])
    g = classify_lines(_case_c_lines(P14, P23), length_scale=0.2)
    assert g.rank == 5 and g.singular
    c = g.find_circuit("two-pencils-sharing-a-line")
    assert c is not None and c.indices == (0, 1, 2, 3) and c.rank == 3
    assert same_line(c.witnesses["common_line"], through(P14, P23))
    pens = c.witnesses["pencils"]
    assert [p["lines"] for p in pens] == [[0, 3], [1, 2]]
    assert np.allclose(pens[0]["point"], P14, atol=1e-12) and np.allclose(pens[1]["point"], P23, atol=1e-12)
    _, B = four_sps_cu_points(0.1, 0.2)
    for p, (i, j) in zip(pens, [(0, 3), (1, 2)], strict=True):  # plane A_i A_j B_j B_i contains B_i, B_j
        n, c0 = p["plane"]["normal"], p["plane"]["offset"]
        assert abs(n @ B[i] - c0) < 1e-12 and abs(n @ B[j] - c0) < 1e-12


def test_paper_b_case_c_as_worded_keeps_rank_6():
    """Fig 3c as printed: legs 1, 4 meet at P14, legs 2, 3 at P23, the points on the
    intersection line of planes A1A2B2B1 and A4A3B3B4.  Those 'planes' exist only if legs 1, 2
    and legs 3, 4 are coplanar; they contain the edges B1B2 and B3B4 (along Y), so the line is
    parallel to Y: P14 = (0.03, 0.05, 0.45), P23 = (0.03, -0.12, 0.45).  The legs then form a
    skew quadrilateral (1-2-3-4, consecutive legs meet), rank 4, and the six lines have rank 6:
    as worded, case (c) is not singular."""
    P14, P23 = np.array([0.03, 0.05, 0.45]), np.array([0.03, -0.12, 0.45])
    L = _case_c_lines(P14, P23)
    g = classify_lines(L, length_scale=0.2)
    rel = {tuple(p["lines"]): p for p in g.pairs}
    for pair, pt in (((0, 3), P14), ((1, 2), P23)):
        assert rel[pair]["relation"] == "intersect" and np.allclose(rel[pair]["point"], pt, atol=1e-12)
    # the worded condition holds: legs 1, 2 and 3, 4 coplanar; P14, P23 on both planes
    for i, j in ((0, 1), (2, 3)):
        pl = rel[(i, j)]["plane"]
        assert rel[(i, j)]["relation"] == "intersect"
        assert abs(pl["normal"] @ P14 - pl["offset"]) < 1e-12 and abs(pl["normal"] @ P23 - pl["offset"]) < 1e-12
    assert sc.rank(L[:4], length_scale=0.2) == 4
    assert (g.rank, g.case, g.circuits) == (6, "general", ())


def test_summary_and_to_dict_are_serialisable():
    g = classify_lines(_case_c_lines(np.array([0.05, 0.03, 0.45]), np.array([-0.12, 0.03, 0.45])),
                       length_scale=0.2)
    d = json.loads(json.dumps(g.to_dict()))
    assert d["rank"] == 5 and d["circuits"][0]["case"] == "two-pencils-sharing-a-line"
    assert d["circuits"][0]["witnesses"]["pencils"][0]["lines"] == [0, 3]
    text = g.summary()
    assert "circuit [0, 1, 2, 3] (rank 3): two-pencils-sharing-a-line" in text
    assert "(0.05, 0.03, 0.45)" in text


# ---------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "lines, kw, message",
    [
        (np.zeros((2, 5)), {}, r"^lines: expected shape \(n, 6\)"),
        (np.zeros((0, 6)), {}, "^lines: at least one line"),
        ([[2, 0, 0, 0, 0, 0]], {}, r"^lines\[0\]: direction part is not a unit vector"),
        ([[1, 0, 0, 0, 0, 0], [1, 0, 0, 1, 0, 0]], {}, r"^lines\[1\]: not a line"),
        ([[1, 0, 0, 0, np.nan, 0]], {}, r"^lines\[0\]: contains NaN"),
        ([[1, 0, 0, 0, 0, 0]], {"length_scale": 0.0}, "^length_scale: must be a positive"),
        ([[1, 0, 0, 0, 0, 0]], {"tol": 0.5}, r"^tol: must be in \(0, 0.01\)"),
    ],
)
def test_bad_input_raises_value_error_naming_the_field(lines, kw, message):
    with pytest.raises(ValueError, match=message):
        classify_lines(lines, **kw)
