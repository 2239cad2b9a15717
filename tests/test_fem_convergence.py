"""Mesh convergence of F0, r_c and l for cup A, frictionless and sticking contact.

The converged reference is the Richardson extrapolation (`fem.postprocess.richardson`) of the
three fidelity levels (coarse, medium, fine: element counts doubled each time with the same
grading, so a constant refinement ratio of 2 and nested vertices) run from u = 0 to 0.9 h1 with
load steps of at most 0.01 of the range and sampled at common u by PCHIP; where the three values
do not converge monotonically the fine level is the reference. The fine level (19 074 DOFs) takes
30-60 s per contact law on one core with these small steps, too long for the default suite, so
the extrapolated curves are stored below, as `benchmarks/bench_mesh_levels.py --detail` prints
them (it reruns all three levels). The slow tests (``-m slow -s``, about a minute) run the coarse and medium levels with the
same load steps against that reference; the cheap default test compares coarse and medium up to
0.6 h1.

The strip width checked here is the force-quartile width of the innermost contact zone
(`fem.postprocess.quartile_width`, the hand-off's `CupResponse.l_m`).
"""

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from fem.cup import compress_cup
from fem.geometry import cup_geometry
from fem.material import NeoHookean
from fem.mesh import FIDELITIES, cup_mesh

GEOMETRY = cup_geometry("A")
U_F0 = np.round(np.arange(0.10, 0.901, 0.05), 4)        # u / h1
U_STRIP = np.round(np.arange(0.30, 0.901, 0.05), 4)     # after the wall has touched down
MAX_STEP = 0.01                                         # load-step cap of the reference runs

#: cup A, E = 4 MPa, nu = 0.49, max_step 0.01: F0 [N] at U_F0; r_c and force-quartile l_q [mm] at
#: U_STRIP. Frictionless: Richardson extrapolation of the levels 36x4, 72x8, 144x16. Sticking: when
#: this reference was made the fine level's path failed at 0.894 h1 (it now reaches 0.9 h1, past
#: the folding stretch, with F0 = 60.1 N, a fold the coarser levels cannot follow), so it is the
#: Richardson extrapolation of an independent family, the former levels 32x3, 64x6, 128x12
#: (`MeshSpec(32, 3, along_grading=-0.5)` and its refinements; 910-12 850 DOFs, uniform layers):
#: where that family is not in the asymptotic range (u = 0.1, 0.2-0.3, 0.85-0.9 h1) its 128x12
#: value, itself ~0.5-1 % off (its levels still move by 0.9-1.3 % between medium and fine there).
#: For frictionless contact the two families' extrapolations agree within 0.2 % up to 0.85 h1
#: (0.9 % at the touchdown, 0.2 h1) and 0.7 % at 0.9 h1. For sticking, the new family run to
#: 0.85 h1 only (where its fine path succeeds) extrapolates to within 1.3 % of this reference
#: (-1.2 % at 0.1 h1, +1.3 % at 0.15 h1, < 0.9 % from 0.2 h1 on outside the touchdown): the
#: sticking reference is good to about 1 %, and the medium level is within 0.84 % of either.
REFERENCE = {
    "frictionless": {"F0": [0.67151, 0.883, 1.0575, 1.3374, 1.7198, 2.1579, 2.6523, 3.2069, 3.8254, 4.5178,
                            5.3006, 6.2098, 7.3151, 8.7499, 10.835, 14.22, 20.479],
                     "r_c": [18.653, 17.992, 17.394, 16.724, 16.083, 15.373, 14.622, 13.844, 13.007, 12.063,
                             10.978, 9.7879, 8.485],
                     "l": [0.69168, 0.84997, 0.98394, 1.1629, 1.3612, 1.5377, 1.7367, 1.9314, 2.1771, 2.4174,
                           2.6474, 2.8247, 2.8983]},
    "sticking": {"F0": [3.8932, 4.5270, 4.9172, 5.0816, 5.1228, 5.0162, 4.8224, 4.5289, 4.1191, 5.6669,
                        11.4921, 16.4732, 20.7202, 26.2395, 34.1724, 45.9371, 64.8415]},
}
#: sticking: the wall rolls over its stuck rim, F0 falls until the middle of the wall touches down
#: (u ~ 0.54 h1) and then rises steeply (x2.5 within 0.05 h1): there the relative F0 error
#: measures where a level puts the touchdown, not how well it resolves a state; left out
STICKING_SMOOTH = (U_F0 < 0.5 - 1e-9) | (U_F0 > 0.65 + 1e-9)


def _curves(level, u_max_over_h1, contact="frictionless", **solver_opts):
    resp = compress_cup(cup_mesh(GEOMETRY, level), NeoHookean(), contact=contact,
                        u_max_m=u_max_over_h1 * GEOMETRY.h1_m, **solver_opts)
    x = resp.u_m / resp.h1_m
    at = lambda y, u: PchipInterpolator(x, y)(u[u <= u_max_over_h1 + 1e-9])     # noqa: E731
    return {"F0": at(resp.F0_N, U_F0), "r_c": 1e3 * at(resp.r_c_m, U_STRIP),
            "l": 1e3 * at(resp.l_m, U_STRIP)}


def test_coarse_level_agrees_with_the_medium_default():
    # cheap version of the study below (frictionless), up to 0.6 h1 with load steps of 0.02 u_max
    # so that the sampling adds little: the coarse F0 within 1 % of the medium one (measured
    # 0.66 %, largest at the touchdown of the wall near 0.2 h1, which the levels place slightly
    # differently); the coarse level is within 1 % of the converged curve up to 0.85 h1
    coarse, medium = (_curves(level, 0.6, max_step=0.02) for level in ("coarse", "medium"))
    assert np.max(np.abs(coarse["F0"] / medium["F0"] - 1)) < 0.01
    assert np.all(np.diff(coarse["F0"]) > 0) and np.all(np.diff(medium["F0"]) > 0)
    # the contact front moves inwards once the wall has touched down (by > 1 mm from 0.3 to 0.6 h1)
    assert medium["r_c"][-1] < medium["r_c"][0] - 1.0


def _levels(contact):
    runs = [_curves(level, 0.9, contact, max_step=MAX_STEP) for level in ("coarse", "medium")]
    ref = REFERENCE[contact]
    print(f"\nmesh convergence, cup A {contact}: coarse and medium against the extrapolation")
    for q, u in (("F0", U_F0), ("r_c", U_STRIP), ("l", U_STRIP)):
        if q not in ref:
            continue
        print(f"{q:>4}: u/h1    coarse    medium  reference   err_c%  err_m%  order")
        for k, x in enumerate(u):
            e = [r[q][k] / ref[q][k] - 1 for r in runs]
            order = np.log2(abs(e[0] / e[1])) if e[1] != 0 else np.inf
            print(f"      {x:4.2f} {runs[0][q][k]:9.4f} {runs[1][q][k]:9.4f} {ref[q][k]:9.4f} "
                  f"{100 * e[0]:7.2f} {100 * e[1]:7.2f} {order:6.2f}")
    return runs


@pytest.fixture(scope="module")
def frictionless():
    return _levels("frictionless")


@pytest.fixture(scope="module")
def sticking():
    return _levels("sticking")


def _error(run, contact, q, mask=slice(None)):
    ref = np.asarray(REFERENCE[contact][q])
    return np.abs(run[q] / ref - 1)[mask]


@pytest.mark.slow
def test_f0_converges_and_the_medium_default_is_within_one_percent(frictionless):
    coarse, medium = (_error(r, "frictionless", "F0") for r in frictionless)
    print("F0 error of coarse / medium [%]:", np.round(100 * coarse, 2).tolist(), np.round(100 * medium, 2).tolist())
    # measured: the medium default (fem.mesh.DEFAULT_FIDELITY) within 0.26 % up to 0.85 h1 and
    # 0.98 % at 0.9 h1, where F0 doubles within 0.1 h1 and the clamped corner at the plate makes
    # the convergence slow (Richardson orders 0.8-1.3 there, 1.9-5.6 below 0.7 h1); the coarse
    # sweep level within 0.86 % up to 0.85 h1 (largest at the touchdown of the wall, 0.2 h1) and
    # 1.69 % at 0.9 h1. Bounds: the default's 1 % promise; the coarse values rounded up
    assert np.max(medium) < 0.01
    assert np.max(coarse[U_F0 <= 0.85 + 1e-9]) < 0.01 and coarse[-1] < 0.02
    # converging: where the coarse level is off by more than 0.2 %, the medium error is at least
    # 1.5 times smaller (observed orders log2(e_c/e_m) measured 1.0-2.0)
    big = coarse > 0.002
    assert np.all(medium[big] < coarse[big] / 1.5)


@pytest.mark.slow
def test_contact_radius_converges(frictionless):
    coarse, medium = (_error(r, "frictionless", "r_c") for r in frictionless)
    # r_c jumps by a node spacing (0.2-0.4 mm at 8-19 mm) as the front passes the nodes: the
    # medium level within 1 % of the extrapolated r_c (0.64 % measured; coarse 1.0 %)
    assert np.max(medium) < 0.01


@pytest.mark.slow
def test_strip_width_converges_within_two_percent(frictionless):
    # the force-quartile width l_q of the innermost contact zone, for u >= 0.7 h1: the medium
    # level within 2 % of the extrapolated l (1.22 % measured; coarse 3.9 %), Richardson orders
    # 1.2-2.3 there. Below 0.7 h1 the strip is 0.7-1.9 mm wide, i.e. 3-8 node spacings of the
    # medium level, and l_q moves by a few % each time the contact front passes a node: the
    # medium level is 1-6 % off there, the coarse 3-13 %, the fine within 2 % from 0.45 h1 on
    coarse, medium = (_error(r, "frictionless", "l", U_STRIP >= 0.7 - 1e-9) for r in frictionless)
    print("l_q error of coarse / medium for u >= 0.7 h1 [%]:", np.round(100 * coarse, 2).tolist(),
          np.round(100 * medium, 2).tolist())
    assert np.max(medium) < 0.02
    assert np.mean(medium) < np.mean(coarse) / 2        # converging (order > 1 on average)


@pytest.mark.slow
def test_sticking_f0_converges_and_the_medium_level_is_within_one_percent(sticking):
    # outside the mid-wall touchdown (STICKING_SMOOTH) the medium level within 1 % (0.79 % measured,
    # also across the touchdown), the coarse 1-3 % off (2.9 % measured at 0.9 h1, 2.2 % at
    # 0.5 h1: the stuck rim corner is a singular point and the rolling rim is resolved by a few
    # elements only); bounds: the medium level's 1 % promise, the coarse measured value rounded up
    coarse, medium = (_error(r, "sticking", "F0", STICKING_SMOOTH) for r in sticking)
    print("sticking F0 error of coarse / medium [%]:", np.round(100 * coarse, 2).tolist(),
          np.round(100 * medium, 2).tolist())
    assert np.max(medium) < 0.01
    assert np.max(coarse) < 0.04
