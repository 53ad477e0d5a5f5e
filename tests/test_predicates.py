"""Exact predicates (cython_ext/predicates.pxi) against a Fraction oracle.

Every check compares the public predicate, the floating-point filter (which
may abstain but must never be wrong) and the exact stage on its own (run on
every input, not only when the filter abstains) with an exact rational
evaluation, and checks the predicate on every permutation of its arguments
(the sign must follow the permutation's parity).
"""
import itertools
import math
import os
import random
from fractions import Fraction

from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from aftmesh import _kernel
from aftmesh._kernel import py_incircle, py_orient2d

EPS = Fraction(1, 2**53)

# Documented exact ranges: each coordinate is 0 or has its magnitude here.
ORIENT_EXP = (-430, 500)
INCIRCLE_EXP = (-190, 250)

# Bounded and derandomized by default; AFTMESH_TEST_PROFILE=long (the
# project's fuzzing profile) runs ten times more, freshly random, examples.
LONG = os.environ.get("AFTMESH_TEST_PROFILE") == "long"
PROFILE = settings(
    max_examples=4000 if LONG else 400,
    derandomize=not LONG,
    database=None,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)


# ---------------------------------------------------------------------------
# Oracle and checking helpers
# ---------------------------------------------------------------------------

def sign(x):
    return (x > 0) - (x < 0)


def orient_oracle(a, b, c):
    (ax, ay), (bx, by), (cx, cy) = [(Fraction(x), Fraction(y)) for x, y in (a, b, c)]
    return sign((bx - ax) * (cy - ay) - (by - ay) * (cx - ax))


def incircle_oracle(a, b, c, d):
    dx, dy = Fraction(d[0]), Fraction(d[1])
    rows = []
    for x, y in (a, b, c):
        ex, ey = Fraction(x) - dx, Fraction(y) - dy
        rows.append((ex, ey, ex * ex + ey * ey))
    (a0, a1, a2), (b0, b1, b2), (c0, c1, c2) = rows
    det = (a2 * (b0 * c1 - c0 * b1)
           + b2 * (c0 * a1 - a0 * c1)
           + c2 * (a0 * b1 - b0 * a1))
    return sign(det)


def naive_orient(a, b, c):
    return sign((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


def naive_incircle(a, b, c, d):
    adx, ady = a[0] - d[0], a[1] - d[1]
    bdx, bdy = b[0] - d[0], b[1] - d[1]
    cdx, cdy = c[0] - d[0], c[1] - d[1]
    return sign((adx * adx + ady * ady) * (bdx * cdy - cdx * bdy)
                + (bdx * bdx + bdy * bdy) * (cdx * ady - adx * cdy)
                + (cdx * cdx + cdy * cdy) * (adx * bdy - bdx * ady))


def parity(perm):
    inversions = sum(1 for i, j in itertools.combinations(range(len(perm)), 2)
                     if perm[i] > perm[j])
    return -1 if inversions % 2 else 1


def flat(points):
    return [coord for p in points for coord in p]


def check_orient(a, b, c):
    """Assert everything about orient2d(a, b, c); return the exact sign."""
    pts = (a, b, c)
    expected = orient_oracle(*pts)
    filt, exact = _kernel._pred_py_orient2d_stages(*flat(pts))
    assert exact == expected, (pts, exact, expected)
    assert filt in (None, expected), (pts, filt, expected)
    for perm in itertools.permutations(range(3)):
        got = py_orient2d(*flat(pts[i] for i in perm))
        assert got == parity(perm) * expected, (pts, perm, got, expected)
    return expected


def check_incircle(a, b, c, d):
    """Assert everything about incircle(a, b, c, d); return the exact sign."""
    pts = (a, b, c, d)
    expected = incircle_oracle(*pts)
    filt, exact = _kernel._pred_py_incircle_stages(*flat(pts))
    assert exact == expected, (pts, exact, expected)
    assert filt in (None, expected), (pts, filt, expected)
    for perm in itertools.permutations(range(4)):
        got = py_incircle(*flat(pts[i] for i in perm))
        assert got == parity(perm) * expected, (pts, perm, got, expected)
    return expected


def in_range(values, exp_range):
    lo, hi = exp_range
    return all(v == 0.0 or 2.0**lo <= abs(v) <= 2.0**hi for v in values)


def nudge(x, ulps):
    """x moved by `ulps` units in the last place."""
    direction = math.inf if ulps > 0 else -math.inf
    for _ in range(abs(ulps)):
        x = math.nextafter(x, direction)
    return x


# ---------------------------------------------------------------------------
# Strategies
# ---------------------------------------------------------------------------

def coords(exp_range):
    lo, hi = exp_range
    mags = st.floats(min_value=2.0**lo, max_value=2.0**hi)
    return st.one_of(st.just(0.0), mags, mags.map(lambda x: -x))


def points_of(coord):
    return st.tuples(coord, coord)


moderate = coords((-30, 30))
ulps = st.integers(min_value=-3, max_value=3)


@st.composite
def lattice_point(draw):
    """(0.5, 0.5) plus a small multiple of 2^-50 or 2^-53 in each coordinate."""
    step = draw(st.sampled_from([2.0**-50, 2.0**-53]))
    i = draw(st.integers(-8, 8))
    j = draw(st.integers(-8, 8))
    return (0.5 + i * step, 0.5 + j * step)


@st.composite
def near_1e7_point(draw):
    """Around (1e7, 1e7) with 1e-9 detail (below the 1.86e-9 spacing there)."""
    i = draw(st.integers(-10**4, 10**4))
    j = draw(st.integers(-10**4, 10**4))
    return (1e7 + i * 1e-9, 1e7 + j * 1e-9)


@st.composite
def near_collinear(draw, base):
    """a, b from `base`; c = a + t (b - a) rounded, then moved a few ulps."""
    a = draw(base)
    b = draw(base)
    t = draw(st.floats(min_value=-2.0, max_value=3.0))
    c = (nudge(a[0] + t * (b[0] - a[0]), draw(ulps)),
         nudge(a[1] + t * (b[1] - a[1]), draw(ulps)))
    return a, b, c


@st.composite
def near_cocircular(draw, center_coord, radius):
    """Four points cos/sin-rounded onto one circle, some moved by ulps."""
    cx = draw(center_coord)
    cy = draw(center_coord)
    r = draw(radius)
    pts = []
    for _ in range(4):
        theta = draw(st.floats(min_value=0.0, max_value=2 * math.pi))
        pts.append((nudge(cx + r * math.cos(theta), draw(ulps)),
                    nudge(cy + r * math.sin(theta), draw(ulps))))
    return pts


# ---------------------------------------------------------------------------
# Constants
# ---------------------------------------------------------------------------

def test_error_bound_constants_are_exact():
    ccw, icc = _kernel._pred_error_bounds()
    assert Fraction(ccw) == (3 + 16 * EPS) * EPS
    assert Fraction(icc) == (10 + 96 * EPS) * EPS


# ---------------------------------------------------------------------------
# Random doubles over the whole documented range
# ---------------------------------------------------------------------------

@PROFILE
@given(points_of(coords(ORIENT_EXP)), points_of(coords(ORIENT_EXP)),
       points_of(coords(ORIENT_EXP)))
def test_orient_random_full_range(a, b, c):
    check_orient(a, b, c)


@PROFILE
@given(points_of(coords(INCIRCLE_EXP)), points_of(coords(INCIRCLE_EXP)),
       points_of(coords(INCIRCLE_EXP)), points_of(coords(INCIRCLE_EXP)))
def test_incircle_random_full_range(a, b, c, d):
    check_incircle(a, b, c, d)


@PROFILE
@given(points_of(moderate), points_of(moderate), points_of(moderate))
def test_orient_random_moderate(a, b, c):
    check_orient(a, b, c)


@PROFILE
@given(points_of(moderate), points_of(moderate), points_of(moderate),
       points_of(moderate))
def test_incircle_random_moderate(a, b, c, d):
    check_incircle(a, b, c, d)


# ---------------------------------------------------------------------------
# Tiny lattice around (0.5, 0.5)
# ---------------------------------------------------------------------------

@PROFILE
@given(lattice_point(), lattice_point(), lattice_point())
def test_orient_tiny_lattice(a, b, c):
    check_orient(a, b, c)


@PROFILE
@given(lattice_point(), lattice_point(), lattice_point(), lattice_point())
def test_incircle_tiny_lattice(a, b, c, d):
    check_incircle(a, b, c, d)


@PROFILE
@given(lattice_point(), lattice_point(), lattice_point(),
       st.integers(ORIENT_EXP[0] + 1, ORIENT_EXP[1] - 1))
def test_orient_tiny_lattice_scaled_to_range_ends(a, b, c, e):
    # Scaling by 2^e is exact, keeps the sign, and moves the configuration
    # anywhere in the documented range (lattice coordinates are in [0.49, 0.51]).
    s = 2.0**e
    check_orient(*[(x * s, y * s) for x, y in (a, b, c)])


@PROFILE
@given(lattice_point(), lattice_point(), lattice_point(), lattice_point(),
       st.integers(INCIRCLE_EXP[0] + 1, INCIRCLE_EXP[1] - 1))
def test_incircle_tiny_lattice_scaled_to_range_ends(a, b, c, d, e):
    s = 2.0**e
    check_incircle(*[(x * s, y * s) for x, y in (a, b, c, d)])


# ---------------------------------------------------------------------------
# Nearly collinear / nearly cocircular
# ---------------------------------------------------------------------------

@PROFILE
@given(near_collinear(points_of(moderate)))
def test_orient_nearly_collinear(abc):
    assume(in_range(flat(abc), ORIENT_EXP))
    check_orient(*abc)


@PROFILE
@given(near_collinear(points_of(st.floats(min_value=-1.0, max_value=1.0))))
def test_orient_nearly_collinear_unit(abc):
    assume(in_range(flat(abc), ORIENT_EXP))
    check_orient(*abc)


@PROFILE
@given(near_cocircular(st.floats(min_value=-100.0, max_value=100.0),
                       st.floats(min_value=1e-3, max_value=1e3)))
def test_incircle_nearly_cocircular(pts):
    assume(in_range(flat(pts), INCIRCLE_EXP))
    check_incircle(*pts)


@PROFILE
@given(near_cocircular(st.just(0.0), st.just(1.0)))
def test_incircle_nearly_cocircular_unit_circle(pts):
    assume(in_range(flat(pts), INCIRCLE_EXP))
    check_incircle(*pts)


# ---------------------------------------------------------------------------
# Coordinates around 1e7 with 1e-9 detail
# ---------------------------------------------------------------------------

@PROFILE
@given(near_1e7_point(), near_1e7_point(), near_1e7_point())
def test_orient_near_1e7(a, b, c):
    check_orient(a, b, c)


@PROFILE
@given(near_collinear(near_1e7_point()))
def test_orient_nearly_collinear_near_1e7(abc):
    check_orient(*abc)


@PROFILE
@given(near_1e7_point(), near_1e7_point(), near_1e7_point(), near_1e7_point())
def test_incircle_near_1e7(a, b, c, d):
    check_incircle(a, b, c, d)


@PROFILE
@given(near_cocircular(st.floats(min_value=1e7 - 1.0, max_value=1e7 + 1.0),
                       st.floats(min_value=1e-6, max_value=1e-2)))
def test_incircle_nearly_cocircular_near_1e7(pts):
    check_incircle(*pts)


# ---------------------------------------------------------------------------
# Symmetries (also checked, over all permutations, inside every check_*)
# ---------------------------------------------------------------------------

@PROFILE
@given(lattice_point(), lattice_point(), lattice_point(), lattice_point())
def test_swapping_two_points_flips_sign(a, b, c, d):
    o = py_orient2d(*a, *b, *c)
    assert py_orient2d(*b, *a, *c) == -o
    assert py_orient2d(*a, *c, *b) == -o
    assert py_orient2d(*b, *c, *a) == o
    i = py_incircle(*a, *b, *c, *d)
    assert py_incircle(*b, *a, *c, *d) == -i
    assert py_incircle(*a, *b, *d, *c) == -i
    assert py_incircle(*d, *b, *c, *a) == -i
    assert py_incircle(*b, *c, *a, *d) == i


# ---------------------------------------------------------------------------
# Exactly degenerate inputs
# ---------------------------------------------------------------------------

# Integer points on x^2 + y^2 = 25 and x^2 + y^2 = 65^2.
CIRCLE_5 = sorted({(sx * x, sy * y) for x, y in [(5, 0), (0, 5), (3, 4), (4, 3)]
                   for sx in (1, -1) for sy in (1, -1)})
CIRCLE_65 = sorted({(sx * x, sy * y)
                    for x, y in [(65, 0), (0, 65), (16, 63), (63, 16), (25, 60),
                                 (60, 25), (33, 56), (56, 33), (39, 52), (52, 39)]
                    for sx in (1, -1) for sy in (1, -1)})


@PROFILE
@given(st.integers(-10**6, 10**6), st.integers(-10**6, 10**6),
       st.integers(-1000, 1000), st.integers(-1000, 1000),
       st.integers(-1000, 1000), st.integers(-1000, 1000),
       st.integers(-60, 60))
def test_orient_exactly_collinear_lattice(x0, y0, vx, vy, m, n, e):
    s = 2.0**e
    a = (x0 * s, y0 * s)
    b = ((x0 + m * vx) * s, (y0 + m * vy) * s)
    c = ((x0 + n * vx) * s, (y0 + n * vy) * s)
    assert check_orient(a, b, c) == 0


@PROFILE
@given(st.sampled_from([CIRCLE_5, CIRCLE_65]).flatmap(
           lambda pts: st.permutations(pts).map(lambda p: p[:4])),
       st.integers(-10**6, 10**6), st.integers(-10**6, 10**6),
       st.integers(-60, 60))
def test_incircle_exactly_cocircular_integers(pts, ox, oy, e):
    s = 2.0**e
    moved = [((x + ox) * s, (y + oy) * s) for x, y in pts]
    assert check_incircle(*moved) == 0


def test_cocircular_and_collinear_examples():
    assert py_incircle(5, 0, 0, 5, -5, 0, 3, 4) == 0
    assert py_incircle(5, 0, 0, 5, -5, 0, 3, 3.99) == 1
    assert py_incircle(5, 0, 0, 5, -5, 0, 3, 4.01) == -1
    assert py_incircle(0, 5, 5, 0, -5, 0, 0, 0) == -1      # clockwise a, b, c
    assert py_orient2d(0, 0, 1, 0, 0, 1) == 1
    assert py_orient2d(0, 0, 0, 1, 1, 0) == -1
    assert py_orient2d(-3, 7, 1, 7, 100, 7) == 0
    # Axis-aligned degeneracies are settled by the filter (zero permanent).
    assert _kernel._pred_py_orient2d_stages(-3, 7, 1, 7, 100, 7) == (0, 0)
    assert _kernel._pred_py_orient2d_stages(2, -1, 2, 5, 2, 9) == (0, 0)
    # Repeated points.
    assert check_orient((1.5, 2.5), (1.5, 2.5), (3.0, -1.0)) == 0
    assert check_incircle((1.5, 2.5), (1.5, 2.5), (3.0, -1.0), (0.1, 0.2)) == 0


# ---------------------------------------------------------------------------
# The exact stage is really needed and really used
# ---------------------------------------------------------------------------

def test_orient_fallback_on_classic_failure_grid():
    # Points just off (0.5, 0.5) against the line through (12, 12), (24, 24):
    # the naive determinant gets many of these wrong.
    u = 2.0**-53
    q, r = (12.0, 12.0), (24.0, 24.0)
    naive_wrong = naive_zero_but_not = undecided = 0
    for i in range(64):
        for j in range(64):
            p = (0.5 + i * u, 0.5 + j * u)
            expected = check_orient(p, q, r)
            naive = naive_orient(p, q, r)
            naive_wrong += naive != expected
            naive_zero_but_not += naive == 0 and expected != 0
            undecided += _kernel._pred_py_orient2d_stages(*p, *q, *r)[0] is None
    assert naive_wrong > 100
    assert naive_zero_but_not > 0
    assert undecided >= naive_wrong


def test_incircle_fallback_on_rounded_circle_points():
    rng = random.Random(20240601)
    naive_wrong = naive_zero_but_not = undecided = 0
    for _ in range(1500):
        cx, cy = rng.uniform(-10, 10), rng.uniform(-10, 10)
        r = rng.uniform(0.1, 10)
        pts = []
        for _ in range(4):
            theta = rng.uniform(0, 2 * math.pi)
            pts.append((cx + r * math.cos(theta), cy + r * math.sin(theta)))
        expected = incircle_oracle(*pts)
        assert py_incircle(*flat(pts)) == expected, pts
        filt, exact = _kernel._pred_py_incircle_stages(*flat(pts))
        assert exact == expected and filt in (None, expected), pts
        naive = naive_incircle(*pts)
        naive_wrong += naive != expected
        naive_zero_but_not += naive == 0 and expected != 0
        undecided += filt is None
    assert naive_wrong > 0
    assert undecided >= naive_wrong


def test_incircle_fallback_naive_zero_near_rectangle_corner():
    # The corners of an axis-aligned rectangle are exactly cocircular.  Moving
    # one corner by a few ulps gives a true determinant far below the
    # rounding noise of the naive evaluation, which then often returns 0 or
    # the wrong sign.
    x0, x1, y0, y1 = 0.1, 1.7, 0.3, 2.9
    step = 2.0**-55
    corners = [(x1, y0), (x0, y1), (x1, y1)]
    naive_zero_but_not = naive_wrong = 0
    for i in range(16):
        for j in range(16):
            a = (x0 + i * step, y0 + j * step)
            expected = check_incircle(a, *corners)
            naive = naive_incircle(a, *corners)
            naive_zero_but_not += naive == 0 and expected != 0
            naive_wrong += naive != expected
    assert naive_zero_but_not > 0
    assert naive_wrong > naive_zero_but_not


def test_outside_range_does_not_crash():
    # No exactness is promised here, only a sign and no memory errors.
    nasty = [math.nan, math.inf, -math.inf, 5e-324, 1e-300, 1e300, 1.7e308, 0.0]
    rng = random.Random(7)
    for _ in range(500):
        p = [rng.choice(nasty + [rng.uniform(-1, 1)]) for _ in range(8)]
        assert py_orient2d(*p[:6]) in (-1, 0, 1)
        assert py_incircle(*p) in (-1, 0, 1)
