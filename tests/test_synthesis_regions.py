"""Solution regions: type/defect classification of spherical 4R against an independent
brute-force grid of the configuration torus; region 2's vertical stripes and sign patterns."""

import numpy as np
import pytest
from scipy import ndimage
from scipy.spatial.transform import Rotation

from spatialmech.synthesis.burmester import burmester_curves
from spatialmech.synthesis.dyads import solution_line
from spatialmech.synthesis.regions import (
    BRANCH, CIRCUIT, ORDER, TYPES, classify_spherical_4r, sign_pattern, solution_region_1, solution_region_2,
)
from spatialmech.synthesis.tasks import get_task

def rot(axis, ang):
    return Rotation.from_rotvec(np.multiply.outer(ang, axis)).as_matrix()

def brute_classify(C, u_in, v_in, u_out, v_out, n=720):
    """Independent grid classification of a spherical 4R through 4 orientations."""
    th = np.linspace(0, 2*np.pi, n, endpoint=False)
    A = rot(v_in, th) @ u_in     # (n,3)
    B = rot(v_out, th) @ u_out   # (n,3)  psi grid
    cb = u_in @ u_out
    F = A @ B.T - cb             # F[theta, psi]
    dB = np.cross(v_out, B)      # dB/dpsi
    Fpsi = A @ dB.T
    Fr = np.roll(F, -1, 0)
    Fc = np.roll(F, -1, 1)
    Frc = np.roll(Fr, -1, 1)
    mn = np.minimum(np.minimum(F, Fr), np.minimum(Fc, Frc))
    mx = np.maximum(np.maximum(F, Fr), np.maximum(Fc, Frc))
    zero = (mn <= 0) & (mx >= 0)
    in_crank = bool(np.all(zero.any(axis=1)))
    out_crank = bool(np.all(zero.any(axis=0)))
    def label_periodic(mask):
        lab, k = ndimage.label(mask, structure=np.ones((3,3)))
        # merge across wrap
        parent = list(range(k+1))
        def find(a):
            while parent[a] != a:
                parent[a] = parent[parent[a]]
                a = parent[a]
            return a
        def union(a,b):
            if a and b:
                parent[find(a)] = find(b)
        for i in range(n):
            for di in (-1,0,1):
                union(lab[i,0], lab[(i+di)%n,-1])
                union(lab[0,i], lab[-1,(i+di)%n])
        roots = np.array([find(i) for i in range(k + 1)])
        return roots[lab]
    circ = label_periodic(zero)
    br = label_periodic(zero & (Fpsi > 0)) * 1 + label_periodic(zero & (Fpsi <= 0)) * 100000
    Cs = np.concatenate([np.eye(3)[None], C])
    def ang(axis, x0, x):
        a = x0 - (x0@axis)*axis
        b = x - (x@axis)*axis
        return np.mod(np.arctan2(axis @ np.cross(a, b), a @ b), 2*np.pi)
    tj = np.array([ang(v_in, u_in, Cj@u_in) for Cj in Cs])
    pj = np.array([ang(v_out, u_out, Cj@u_out) for Cj in Cs])
    def cell(t, p):
        i = int(np.floor(t/(2*np.pi)*n)) % n
        k = int(np.floor(p/(2*np.pi)*n)) % n
        # nearest zero cell in a small window
        best=None
        for di in range(-2,3):
            for dk in range(-2,3):
                ii=(i+di)%n
                kk=(k+dk)%n
                if zero[ii,kk]:
                    dd=di*di+dk*dk
                    if best is None or dd < best[0]:
                        best = (dd, ii, kk)
        return best[1], best[2]
    cells = [cell(t,p) for t,p in zip(tj,pj, strict=True)]
    circuits = [circ[c] for c in cells]
    branches = [br[c] for c in cells]
    circuit_defect = len(set(circuits))>1
    branch_defect = (not circuit_defect) and (not in_crank) and len(set(branches))>1
    order_defect = False
    if not circuit_defect and not branch_defect:
        if in_crank:
            ph = np.mod(tj[1:]-tj[0], 2*np.pi)
            d = np.diff(ph)
            order_defect = not (np.all(d>0) or np.all(d<0))
        else:
            lab = branches[0]
            cols = np.flatnonzero(~(br==lab).any(axis=1))
            ref = th[cols[len(cols)//2]]
            ph = np.mod(tj-ref, 2*np.pi)
            d=np.diff(ph)
            order_defect = not (np.all(d>0) or np.all(d<0))
    typ = {(True,False):0,(False,True):1,(True,True):2,(False,False):3}[(in_crank,out_crank)]
    return typ, circuit_defect*1 + branch_defect*2 + order_defect*4


@pytest.fixture(scope="module")
def task():
    return get_task("rccc-four-positions")


@pytest.fixture(scope="module")
def curves(task):
    return burmester_curves(task, samples=90)


@pytest.fixture(scope="module")
def region(task, curves):
    return solution_region_1(task, curves)


@pytest.mark.slow
def test_region1_classification_matches_brute_force_grid(task, curves, region):
    """Type and circuit/branch/order defects of cells of every kind agree with an independent
    classification on a 720 x 720 grid of the (input, output) angle torus: crank = the zero set
    meets every input column; circuits = connected components; branches = components split by
    the sign of dF/dpsi (input dead centres); order = the input angles' sequence."""
    rng = np.random.default_rng(3)
    checked = set()
    for t in range(4):
        for bits in (0, CIRCUIT, BRANCH, ORDER):
            cells = np.argwhere((region.type == t) & (region.defects == bits))
            if len(cells) == 0:
                continue
            for i, k in cells[rng.choice(len(cells), size=min(1, len(cells)), replace=False)]:
                got = classify_spherical_4r(task.C, curves.u[i], curves.v[i], curves.u[k], curves.v[k])
                assert (int(got[0]), int(got[1])) == (t, bits)
                assert brute_classify(task.C, curves.u[i], curves.v[i], curves.u[k], curves.v[k]) == (t, bits), (i, k)
                checked.add((t, bits))
    # every type and every defect kind was exercised
    assert {t for t, _ in checked} == {0, 1, 2, 3}
    assert {b for _, b in checked} == {0, CIRCUIT, BRANCH, ORDER}


def test_region1_is_symmetric_under_swapping_input_and_output(region):
    """Swapping the dyads turns crank-rocker into rocker-crank (and keeps the other types)."""
    T = region.type
    swap = np.array([1, 0, 2, 3, 4])[T.T]
    assert np.array_equal(T, swap)
    assert np.all(T.diagonal() == TYPES.index("degenerate"))


def test_region1_counts_table1(region):
    """Measured on table 1 (90 samples per branch, 180 x 180 cells)."""
    c = region.counts()
    assert region.n_cells == 180 * 180
    assert c["degenerate"] == 180
    assert c["crank-rocker"] == c["rocker-crank"] > 0
    assert c["defect_free"] > 0 and region.mask("crank-rocker").any()


def test_region2_is_vertical_stripes_of_slide_sign_patterns(task, curves):
    """Trap: the input C slide depends on the input dyad only."""
    li = solution_line(task, curves.u[10], curves.v[10])
    lo = solution_line(task, curves.u[150], curves.v[150])
    r2 = solution_region_2(li, lo, np.linspace(-100, 100, 41), np.linspace(-50, 50, 21))
    grid = r2.pattern_grid
    assert grid.shape == (41, 21)
    assert np.all(grid == grid[:, :1])
    assert np.allclose(np.cumsum(r2.increments, axis=1), r2.slides_in)
    assert len(set(r2.patterns.tolist())) >= 2
    assert set("".join(r2.patterns.tolist())) <= set("+-0")
    d = r2.to_dict()
    assert sum(d["pattern_counts"].values()) == 41


def test_sign_pattern():
    assert sign_pattern([[1.0, -2.0, 0.0], [0.5, 0.5, -0.5]], zero=1e-12).tolist() == ["+-0", "++-"]
