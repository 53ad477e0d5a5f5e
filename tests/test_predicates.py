"""Exact predicates (cython_ext/predicates.pxi) against a Fraction oracle.

Every check compares the public predicate, the floating-point filter (which
may abstain but must never be wrong), the adaptive stage B (which must
decide when every coordinate difference is exact, unless for incircle a lift
or minor needs more than three doubles; with inexact differences orient2d's
stage B abstains and incircle's may decide) and the exact stage C on its own
(all run on every input, not only when the previous stage abstains) with an
exact rational evaluation, and checks the predicate on every permutation of
its arguments (the sign must follow the permutation's parity).
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
    det = a2 * (b0 * c1 - c0 * b1) + b2 * (c0 * a1 - a0 * c1) + c2 * (a0 * b1 - b0 * a1)
    return sign(det)


def naive_orient(a, b, c):
    return sign((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


def naive_incircle(a, b, c, d):
    adx, ady = a[0] - d[0], a[1] - d[1]
    bdx, bdy = b[0] - d[0], b[1] - d[1]
    cdx, cdy = c[0] - d[0], c[1] - d[1]
    return sign(
        (adx * adx + ady * ady) * (bdx * cdy - cdx * bdy)
        + (bdx * bdx + bdy * bdy) * (cdx * ady - adx * cdy)
        + (cdx * cdx + cdy * cdy) * (adx * bdy - bdx * ady)
    )


def parity(perm):
    inversions = sum(1 for i, j in itertools.combinations(range(len(perm)), 2) if perm[i] > perm[j])
    return -1 if inversions % 2 else 1


def flat(points):
    return [coord for p in points for coord in p]


def differences_exact(pts):
    """Whether every coordinate difference p - pts[base] the stages use is exact
    (base: a for orient2d, d for incircle), checked with Fractions."""
    base = pts[0] if len(pts) == 3 else pts[3]
    return all(
        Fraction(p[k] - base[k]) == Fraction(p[k]) - Fraction(base[k]) for p in pts for k in (0, 1)
    )


def check_orient(a, b, c):
    """Assert everything about orient2d(a, b, c); return the exact sign."""
    pts = (a, b, c)
    expected = orient_oracle(*pts)
    filt, exact = _kernel._pred_py_orient2d_stages(*flat(pts))
    assert exact == expected, (pts, exact, expected)
    assert filt in (None, expected), (pts, filt, expected)
    stage_b = _kernel.py_orient2d_stage_b(*flat(pts))
    # With exact differences stage B never abstains.
    assert stage_b == (expected if differences_exact(pts) else None), (pts, stage_b, expected)
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
    stage_b, path = _kernel._pred_py_incircle_stage_b_path(*flat(pts))
    assert stage_b == _kernel.py_incircle_stage_b(*flat(pts))
    if differences_exact(pts):
        assert path in ("sweep1", "sweeps", "grown", "split"), (pts, path)
    else:
        assert path in ("tails", "inexact", "split"), (pts, path)
    if path in ("inexact", "split"):
        assert stage_b is None, (pts, stage_b, path)
    else:
        assert stage_b == expected, (pts, stage_b, expected, path)
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
    i = draw(st.integers(-(10**4), 10**4))
    j = draw(st.integers(-(10**4), 10**4))
    return (1e7 + i * 1e-9, 1e7 + j * 1e-9)


@st.composite
def near_collinear(draw, base):
    """a, b from `base`; c = a + t (b - a) rounded, then moved a few ulps."""
    a = draw(base)
    b = draw(base)
    t = draw(st.floats(min_value=-2.0, max_value=3.0))
    c = (nudge(a[0] + t * (b[0] - a[0]), draw(ulps)), nudge(a[1] + t * (b[1] - a[1]), draw(ulps)))
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
        pts.append(
            (
                nudge(cx + r * math.cos(theta), draw(ulps)),
                nudge(cy + r * math.sin(theta), draw(ulps)),
            )
        )
    return pts


# ---------------------------------------------------------------------------
# Constants
# ---------------------------------------------------------------------------


def test_error_bound_constants_are_exact():
    ccw, icc = _kernel._pred_error_bounds()
    assert Fraction(ccw) == (3 + 16 * EPS) * EPS
    assert Fraction(icc) == (10 + 96 * EPS) * EPS
    assert Fraction(_kernel._pred_error_bound_tails()) == 48 * EPS * EPS


# ---------------------------------------------------------------------------
# Random doubles over the whole documented range
# ---------------------------------------------------------------------------


@PROFILE
@given(points_of(coords(ORIENT_EXP)), points_of(coords(ORIENT_EXP)), points_of(coords(ORIENT_EXP)))
def test_orient_random_full_range(a, b, c):
    check_orient(a, b, c)


@PROFILE
@given(
    points_of(coords(INCIRCLE_EXP)),
    points_of(coords(INCIRCLE_EXP)),
    points_of(coords(INCIRCLE_EXP)),
    points_of(coords(INCIRCLE_EXP)),
)
def test_incircle_random_full_range(a, b, c, d):
    check_incircle(a, b, c, d)


@PROFILE
@given(points_of(moderate), points_of(moderate), points_of(moderate))
def test_orient_random_moderate(a, b, c):
    check_orient(a, b, c)


@PROFILE
@given(points_of(moderate), points_of(moderate), points_of(moderate), points_of(moderate))
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
@given(
    lattice_point(),
    lattice_point(),
    lattice_point(),
    st.integers(ORIENT_EXP[0] + 1, ORIENT_EXP[1] - 1),
)
def test_orient_tiny_lattice_scaled_to_range_ends(a, b, c, e):
    # Scaling by 2^e is exact, keeps the sign, and moves the configuration
    # anywhere in the documented range (lattice coordinates are in [0.49, 0.51]).
    s = 2.0**e
    check_orient(*[(x * s, y * s) for x, y in (a, b, c)])


@PROFILE
@given(
    lattice_point(),
    lattice_point(),
    lattice_point(),
    lattice_point(),
    st.integers(INCIRCLE_EXP[0] + 1, INCIRCLE_EXP[1] - 1),
)
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
@given(
    near_cocircular(
        st.floats(min_value=-100.0, max_value=100.0), st.floats(min_value=1e-3, max_value=1e3)
    )
)
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
@given(
    near_cocircular(
        st.floats(min_value=1e7 - 1.0, max_value=1e7 + 1.0),
        st.floats(min_value=1e-6, max_value=1e-2),
    )
)
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
CIRCLE_5 = sorted(
    {
        (sx * x, sy * y)
        for x, y in [(5, 0), (0, 5), (3, 4), (4, 3)]
        for sx in (1, -1)
        for sy in (1, -1)
    }
)
CIRCLE_65 = sorted(
    {
        (sx * x, sy * y)
        for x, y in [
            (65, 0),
            (0, 65),
            (16, 63),
            (63, 16),
            (25, 60),
            (60, 25),
            (33, 56),
            (56, 33),
            (39, 52),
            (52, 39),
        ]
        for sx in (1, -1)
        for sy in (1, -1)
    }
)


@PROFILE
@given(
    st.integers(-(10**6), 10**6),
    st.integers(-(10**6), 10**6),
    st.integers(-1000, 1000),
    st.integers(-1000, 1000),
    st.integers(-1000, 1000),
    st.integers(-1000, 1000),
    st.integers(-60, 60),
)
def test_orient_exactly_collinear_lattice(x0, y0, vx, vy, m, n, e):
    s = 2.0**e
    a = (x0 * s, y0 * s)
    b = ((x0 + m * vx) * s, (y0 + m * vy) * s)
    c = ((x0 + n * vx) * s, (y0 + n * vy) * s)
    assert check_orient(a, b, c) == 0


@PROFILE
@given(
    st.sampled_from([CIRCLE_5, CIRCLE_65]).flatmap(
        lambda pts: st.permutations(pts).map(lambda p: p[:4])
    ),
    st.integers(-(10**6), 10**6),
    st.integers(-(10**6), 10**6),
    st.integers(-60, 60),
)
def test_incircle_exactly_cocircular_integers(pts, ox, oy, e):
    s = 2.0**e
    moved = [((x + ox) * s, (y + oy) * s) for x, y in pts]
    assert check_incircle(*moved) == 0


_RECT_COORD = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False).filter(
    lambda v: in_range([v], INCIRCLE_EXP)
)


@PROFILE
@given(_RECT_COORD, _RECT_COORD, _RECT_COORD, _RECT_COORD, st.integers(0, 3), st.integers(-2, 2))
def test_incircle_axis_rectangles_and_their_neighbours(x0, x1, y0, y1, moved, ulps):
    # The corners of an axis-parallel rectangle (incircle's shortcut answers 0 for
    # them without the adaptive stage), every order checked by check_incircle; with
    # one corner moved by a few ulps along x the shortcut must not apply: the four
    # points are cocircular again only where the move lands on a corner's x (no move,
    # or onto the other corner of that side, a repeated point).
    assume(x0 != x1 and y0 != y1)
    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    assert check_incircle(*corners) == 0
    x, y = corners[moved]
    corners[moved] = (nudge(x, ulps), y)
    assume(in_range(corners[moved], INCIRCLE_EXP))  # not 0 moved to a subnormal
    expected = check_incircle(*corners)
    assert (expected == 0) == (corners[moved][0] in (x0, x1))


def test_cocircular_and_collinear_examples():
    assert py_incircle(5, 0, 0, 5, -5, 0, 3, 4) == 0
    assert py_incircle(5, 0, 0, 5, -5, 0, 3, 3.99) == 1
    assert py_incircle(5, 0, 0, 5, -5, 0, 3, 4.01) == -1
    assert py_incircle(0, 5, 5, 0, -5, 0, 0, 0) == -1  # clockwise a, b, c
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


# ---------------------------------------------------------------------------
# Stage B: exact coordinate differences (the common case for nearby points)
# ---------------------------------------------------------------------------

STAGE_B_DECIDED = ("sweep1", "sweeps", "grown")


def check_incircle_stage_b(pts):
    """check_incircle, and stage B (exact differences) must decide on its own."""
    expected = check_incircle(*pts)
    verdict, path = _kernel._pred_py_incircle_stage_b_path(*flat(pts))
    assert path in STAGE_B_DECIDED and verdict == expected, (pts, verdict, path, expected)
    return expected


@st.composite
def equilateral_hexagon(draw):
    """Four of the six neighbours of a point of an equilateral lattice (spacing h,
    any rotation) near (0.3, 0.7), each coordinate rounded: cocircular before
    rounding, so the determinant is tiny (or 0)."""
    cx = draw(st.floats(0.26, 0.45))
    cy = draw(st.floats(0.55, 0.95))
    h = draw(st.floats(1e-4, 0.05))
    t0 = draw(st.floats(0.0, math.pi))
    ks = draw(st.permutations(range(6)))[:4]
    return [
        (cx + h * math.cos(t0 + k * math.pi / 3), cy + h * math.sin(t0 + k * math.pi / 3))
        for k in ks
    ]


@st.composite
def lattice_hexagon(draw):
    """The same for lattice points o + i*e1 + j*e2 computed in floating point.
    (All coordinates stay within [0.14, 0.56] x [0.44, 0.86] and the four
    points within 2h of each other, so every difference is exact by Sterbenz.)"""
    ox = draw(st.floats(0.3, 0.4))
    oy = draw(st.floats(0.6, 0.7))
    h = draw(st.floats(1e-3, 0.01))
    t = draw(st.floats(0.0, math.pi))
    e1 = (h * math.cos(t), h * math.sin(t))
    e2 = (h * math.cos(t + math.pi / 3), h * math.sin(t + math.pi / 3))
    i = draw(st.integers(1, 8))
    j = draw(st.integers(1, 8))
    nb = [(i + 1, j), (i, j + 1), (i - 1, j + 1), (i - 1, j), (i, j - 1), (i + 1, j - 1)]
    ks = draw(st.permutations(range(6)))[:4]
    return [
        (ox + nb[k][0] * e1[0] + nb[k][1] * e2[0], oy + nb[k][0] * e1[1] + nb[k][1] * e2[1])
        for k in ks
    ]


@st.composite
def small_circle(draw):
    """Points on a circle of radius 1e-6 .. 0.05 near (0.3, 0.7), moved by a few
    ulps (coordinates within a factor 2 of each other: exact differences)."""
    cx = draw(st.floats(0.29, 0.31))
    cy = draw(st.floats(0.69, 0.71))
    r = 10.0 ** draw(st.floats(-6.0, -1.3))
    pts = []
    for _ in range(4):
        theta = draw(st.floats(0.0, 2 * math.pi))
        pts.append(
            (
                nudge(cx + r * math.cos(theta), draw(ulps)),
                nudge(cy + r * math.sin(theta), draw(ulps)),
            )
        )
    return pts


@PROFILE
@given(equilateral_hexagon())
def test_stage_b_equilateral_hexagon(pts):
    check_incircle_stage_b(pts)


@PROFILE
@given(lattice_hexagon())
def test_stage_b_lattice_hexagon(pts):
    check_incircle_stage_b(pts)


@PROFILE
@given(small_circle())
def test_stage_b_small_circles(pts):
    check_incircle_stage_b(pts)


@PROFILE
@given(equilateral_hexagon(), st.integers(INCIRCLE_EXP[0] + 2, INCIRCLE_EXP[1] - 2))
def test_stage_b_hexagon_scaled_to_range_ends(pts, e):
    # Scaling by 2^e is exact and keeps every difference exact.
    s = 2.0**e
    check_incircle_stage_b([(x * s, y * s) for x, y in pts])


@PROFILE
@given(
    st.sampled_from([CIRCLE_5, CIRCLE_65]).flatmap(
        lambda pts: st.permutations(pts).map(lambda p: p[:4])
    ),
    st.integers(-(10**6), 10**6),
    st.integers(-(10**6), 10**6),
    st.integers(-120, 120),
)
def test_stage_b_integer_circles_scaled(pts, ox, oy, e):
    # Exactly cocircular; the differences (x - x') * 2^e are exact.
    s = 2.0**e
    moved = [((x + ox) * s, (y + oy) * s) for x, y in pts]
    assert check_incircle_stage_b(moved) == 0


@PROFILE
@given(
    st.floats(0.25, 0.5),
    st.floats(0.25, 0.5),
    st.floats(0.5, 1.0),
    st.floats(0.5, 1.0),
    st.permutations(range(4)),
    st.integers(-150, 200),
)
def test_stage_b_rectangles(x1, x2, y1, y2, order, e):
    # Corners of an axis-aligned rectangle are exactly cocircular, whatever
    # the doubles; full-width coordinates make the zero hard to see (several
    # sweeps, sometimes growing).
    s = 2.0**e
    corners = [(x1 * s, y1 * s), (x2 * s, y1 * s), (x2 * s, y2 * s), (x1 * s, y2 * s)]
    assert check_incircle_stage_b([corners[i] for i in order]) == 0


def test_stage_b_pinned_grown_path():
    # A scaled rectangle whose zero determinant the certificate does not see
    # within the sweeps: decided by growing the components.
    pts = [
        (-6.479526483929613e-14, -1.901272885017952e-15),
        (-2.4760177410006713e-14, -4.019328122107341e-14),
        (-6.479526483929613e-14, -4.019328122107341e-14),
        (-2.4760177410006713e-14, -1.901272885017952e-15),
    ]
    assert _kernel._pred_py_incircle_stage_b_path(*flat(pts)) == (0, "grown")
    assert check_incircle_stage_b(pts) == 0


def test_stage_b_decides_the_lattice_cases_the_filter_leaves():
    # The point of stage B: nearly every input the filter cannot decide, on
    # rounded lattices and circles, is decided by stage B (stage C unused).
    rng = random.Random(20240917)
    undecided = 0
    for _ in range(2000):
        cx, cy = rng.uniform(0.26, 0.45), rng.uniform(0.55, 0.95)
        h, t0 = rng.uniform(1e-3, 0.02), rng.uniform(0, math.pi)
        ks = rng.sample(range(6), 4)
        pts = [
            (cx + h * math.cos(t0 + k * math.pi / 3), cy + h * math.sin(t0 + k * math.pi / 3))
            for k in ks
        ]
        filt, _ = _kernel._pred_py_incircle_stages(*flat(pts))
        if filt is None:
            undecided += 1
            verdict, path = _kernel._pred_py_incircle_stage_b_path(*flat(pts))
            assert path in STAGE_B_DECIDED and verdict == incircle_oracle(*pts), (pts, path)
    assert undecided > 500


# Inexact differences: incircle's stage B decides with the tail bound (T) or
# abstains; stage C decides.


@PROFILE
@given(
    points_of(coords((-80, -60))),
    points_of(coords((-2, 2))),
    points_of(coords((-80, -60))),
    points_of(coords((-2, 2))),
)
def test_stage_b_inexact_differences(a, b, c, d):
    # Coordinates near 1 against coordinates near 1e-20: a difference like
    # 1.0 - 1e-20 is not a double.  check_incircle / check_orient assert
    # that stage B is right or abstains, and that orient2d's abstains.
    assume(not differences_exact((a, b, c, d)))
    check_incircle(a, b, c, d)
    assert _kernel._pred_py_incircle_stage_b_path(*flat((a, b, c, d)))[1] in (
        "tails",
        "inexact",
        "split",
    )
    check_orient(d, a, b)
    check_orient(a, c, d)


@st.composite
def diagonal_trapezoid(draw):
    """Like the boundary layer of a mesh of the unit square: (s, 0), (0, s),
    (u, r), (r', u) with s, u on a grid of step h, r = h sqrt(3)/2 and r' = r
    moved by a few ulps (the mesher computes the two sides differently).
    Nearly symmetric about the diagonal, so nearly cocircular (exactly, if
    r' == r); far apart and near the axes, so most differences are inexact."""
    h = draw(st.sampled_from([0.01, 0.005, 0.0025, 0.001]))
    n = int(round(1 / h))
    s = draw(st.integers(1, n)) * h
    u = draw(st.integers(1, n)) * h
    r = h * math.sqrt(3) / 2
    pts = [(s, 0.0), (0.0, s), (u, r), (nudge(r, draw(ulps)), u)]
    return [pts[i] for i in draw(st.permutations(range(4)))]


@PROFILE
@given(diagonal_trapezoid())
def test_stage_b_inexact_differences_large_configurations(pts):
    check_incircle(*pts)


def test_stage_b_tails_decide_large_configurations():
    # With r' != r these are not cocircular; the filter leaves all of them,
    # and stage B decides nearly all with the tail bound (T).
    rng = random.Random(5)
    undecided = tails = 0
    for _ in range(1500):
        h = rng.choice([0.01, 0.005, 0.0025])
        n = int(round(1 / h))
        s, u, r = rng.randint(1, n) * h, rng.randint(1, n) * h, h * math.sqrt(3) / 2
        pts = [(s, 0.0), (0.0, s), (u, r), (nudge(r, rng.choice([-2, -1, 1, 2])), u)]
        rng.shuffle(pts)
        if _kernel._pred_py_incircle_stages(*flat(pts))[0] is None:
            undecided += 1
            verdict, path = _kernel._pred_py_incircle_stage_b_path(*flat(pts))
            if path == "tails":
                tails += 1
                assert verdict == incircle_oracle(*pts), pts
    assert undecided > 300 and tails > 0.9 * undecided, (undecided, tails)


def test_stage_b_tails_pinned_mesh_inputs():
    # Met in a mesh of the unit square (h = 0.0025), left by the filter.
    for r in (
        [0.1825, 0.0, 0.00216506350946108, 0.15375, 0.15375, 0.0021650635094610958, 0.0, 0.1825],
        [
            0.002165063509461112,
            0.38125,
            0.38625,
            0.0021650635094610958,
            0.002165063509461112,
            0.38625,
            0.38125,
            0.0021650635094610958,
        ],
        [
            0.31875,
            0.9978349364905389,
            0.002165063509461112,
            0.70875,
            0.00216506350946108,
            0.6812499999999999,
            0.29125,
            0.9978349364905389,
        ],
    ):
        pts = [(r[2 * i], r[2 * i + 1]) for i in range(4)]
        assert _kernel._pred_py_incircle_stages(*r)[0] is None
        assert _kernel._pred_py_incircle_stage_b_path(*r) == (incircle_oracle(*pts), "tails")
        check_incircle(*pts)


@PROFILE
@given(
    st.floats(-0.5, -0.25),
    st.floats(0.25, 1.0),
    st.floats(-0.5, -0.25),
    st.floats(0.25, 1.0),
    st.permutations(range(4)),
)
def test_stage_b_inexact_differences_zero_determinant(x1, x2, y1, y2, order):
    # A rectangle straddling both axes: exactly cocircular, differences
    # mostly inexact.  No bound can show a zero: stage B must abstain (or,
    # if all differences happen to be exact, decide 0), and stage C gives 0.
    corners = [(x1, y1), (x2, y1), (x2, y2), (x1, y2)]
    pts = [corners[i] for i in order]
    assert check_incircle(*pts) == 0
    verdict, path = _kernel._pred_py_incircle_stage_b_path(*flat(pts))
    assert verdict in (None, 0) and path != "tails", (pts, verdict, path)


def test_stage_b_near_origin_all_paths_agree():
    # Nearly cocircular points around the origin: differences of coordinates
    # of opposite signs are sums, often inexact.
    rng = random.Random(99)
    inexact = 0
    for _ in range(400):
        r = rng.uniform(1e-3, 1.0)
        pts = [
            (r * math.cos(t), r * math.sin(t))
            for t in (rng.uniform(0, 2 * math.pi) for _ in range(4))
        ]
        check_incircle(*pts)
        inexact += not differences_exact(pts)
    assert inexact > 100


@PROFILE
@given(
    st.floats(0.5, 1.0),
    st.floats(0.5, 1.0),
    st.floats(0.5, 1.0),
    st.floats(0.5, 1.0),
    st.integers(-140, -100),
    points_of(coords((-10, 10))),
)
def test_stage_b_split_abstains(x1, y1, x2, y2, e, a):
    # d at the origin makes every difference exact, but a minor
    # bdx*cdy - cdx*bdy with bdx, cdy ~ 1 and cdx, bdy ~ 2^e spans far more
    # than 158 bits: stage B cannot split it and abstains ('split' path,
    # allowed by check_incircle); stage C decides.
    s = 2.0**e
    b, c, d = (x1, y1 * s), (x2 * s, y2), (0.0, 0.0)
    check_incircle(a, b, c, d)


def test_stage_b_split_example():
    pts = [
        (0.75, 0.3),
        (0.7654321, 0.8765432 * 2.0**-120),
        (0.6789012 * 2.0**-120, 0.5432109),
        (0.0, 0.0),
    ]
    assert _kernel._pred_py_incircle_stage_b_path(*flat(pts)) == (None, "split")
    check_incircle(*pts)


# orient2d's stage B.


@PROFILE
@given(near_collinear(points_of(st.floats(min_value=0.26, max_value=0.49))))
def test_orient_stage_b_nearly_collinear(abc):
    # All coordinates in one binade: every difference is exact (Sterbenz), so
    # stage B decides (check_orient asserts it).
    assume(all(0.25 <= v < 0.5 for v in flat(abc)))
    assert differences_exact(abc)
    check_orient(*abc)


# The sign readers of stage B on their own.


@st.composite
def cancelling_doubles(draw):
    """Up to 54 doubles of very different magnitudes whose sum nearly cancels:
    random values, some repeated with the opposite sign and moved by ulps."""
    base = draw(st.lists(st.floats(min_value=0.5, max_value=1.0), min_size=1, max_size=20))
    vals = [
        draw(st.sampled_from([1.0, -1.0])) * v * 2.0 ** draw(st.integers(-200, 200)) for v in base
    ]
    back = draw(st.lists(st.sampled_from(range(len(vals))), max_size=27))
    vals += [nudge(-vals[i], draw(st.integers(-2, 2))) for i in back]
    vals = vals[:54]
    return draw(st.permutations(vals))


@PROFILE
@given(cancelling_doubles(), st.integers(1, 4))
def test_stage_b_sign_readers(vals, sweeps):
    exact = sum(Fraction(v) for v in vals)
    cert, swept, grown = _kernel._pred_py_sum_sign(vals, sweeps)
    assert sum(Fraction(v) for v in swept) == exact  # sweeps keep the sum
    assert cert in (None, sign(exact)), (vals, cert)
    assert grown == sign(exact), (vals, grown)


def test_stage_b_sign_readers_examples():
    assert _kernel._pred_py_sum_sign([1.0, -1.0, 1e-30], 1)[0] == 1
    # One sweep leaves 1e-16 below a zero top: not certified, a second sweep is.
    assert _kernel._pred_py_sum_sign([1.0, 1e-16, -1.0], 1)[0] is None
    assert _kernel._pred_py_sum_sign([1.0, 1e-16, -1.0], 2)[0] == 1
    assert _kernel._pred_py_sum_sign([0.0, 0.0], 1)[0] == 0
    assert _kernel._pred_py_sum_sign([2.0**-1000, -(2.0**-1000)], 1)[0] == 0


# ---------------------------------------------------------------------------
# surely_acute: the certificate that lets legalize_meshed skip incircle
# ---------------------------------------------------------------------------


def dot_oracle(a, b, p):
    """Exact sign of (a - p).(b - p): > 0 when the angle at p is acute."""
    (ax, ay), (bx, by), (px, py) = [(Fraction(x), Fraction(y)) for x, y in (a, b, p)]
    return sign((ax - px) * (bx - px) + (ay - py) * (by - py))


def check_acute(a, b, p):
    """surely_acute may abstain (False) but never certifies an angle that is not
    acute, in either order of a and b."""
    got = _kernel._pred_py_surely_acute(*flat((a, b, p)))
    assert got == _kernel._pred_py_surely_acute(*flat((b, a, p)))
    if got:
        assert dot_oracle(a, b, p) > 0, (a, b, p)
    return got


def thales_point(a, b, theta, ulps_x, ulps_y):
    """The point at angle theta on the circle with diameter ab (Thales: the angle
    there facing ab is right), rounded, then moved by the given ulps."""
    mx, my = 0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])
    r = 0.5 * math.hypot(b[0] - a[0], b[1] - a[1])
    return nudge(mx + r * math.cos(theta), ulps_x), nudge(my + r * math.sin(theta), ulps_y)


angles = st.floats(min_value=0.0, max_value=2 * math.pi)


@st.composite
def near_right_angle(draw, coord):
    """a, b from `coord` and p near their Thales circle: about a right angle at p."""
    a = draw(coord)
    b = draw(coord)
    return a, b, thales_point(a, b, draw(angles), draw(ulps), draw(ulps))


@PROFILE
@given(points_of(coords(ORIENT_EXP)), points_of(coords(ORIENT_EXP)), points_of(coords(ORIENT_EXP)))
def test_surely_acute_random_full_range(a, b, p):
    check_acute(a, b, p)


@PROFILE
@given(near_right_angle(points_of(moderate)))
def test_surely_acute_near_right_angles(abp):
    check_acute(*abp)


@PROFILE
@given(near_right_angle(points_of(st.floats(min_value=-1.0, max_value=1.0))))
def test_surely_acute_near_right_angles_unit(abp):
    check_acute(*abp)


# Seeded near-right angles in the unit square: enough that plain floating point gets
# the sign of some dot products wrong (the sweep asserts it does), so a certificate
# without its error bound would be caught.
THALES_SWEEP = 20000


def test_surely_acute_never_certifies_what_rounding_gets_wrong():
    rng = random.Random(20261203)
    rounding_wrong = 0
    for _ in range(THALES_SWEEP):
        a = (rng.uniform(-1, 1), rng.uniform(-1, 1))
        b = (rng.uniform(-1, 1), rng.uniform(-1, 1))
        p = thales_point(a, b, rng.uniform(0, 2 * math.pi), rng.randint(-3, 3), rng.randint(-3, 3))
        exact = dot_oracle(a, b, p)
        plain = (a[0] - p[0]) * (b[0] - p[0]) + (a[1] - p[1]) * (b[1] - p[1])
        rounding_wrong += (plain > 0) != (exact > 0)
        assert not check_acute(a, b, p) or exact > 0
    assert rounding_wrong > 0


@PROFILE
@given(near_right_angle(near_1e7_point()))
def test_surely_acute_near_right_angles_near_1e7(abp):
    check_acute(*abp)


@PROFILE
@given(lattice_point(), lattice_point(), lattice_point())
def test_surely_acute_tiny_lattice(a, b, p):
    check_acute(a, b, p)


@st.composite
def thales_quad(draw, coord):
    """a, b and two points rounded onto the circle with diameter ab, one on each side
    (two angles of about 90 degrees facing ab, and four nearly cocircular points)."""
    a, b, c = draw(near_right_angle(coord))
    return a, b, c, thales_point(a, b, draw(angles), draw(ulps), draw(ulps))


def check_edge_certificate(a, b, c, d):
    """legalize_meshed skips incircle(a, b, c, d) when the angles at c and d facing
    the edge ab (c left of a->b, d right of it) are both surely acute: d must then
    be strictly outside the circle through a, b, c."""
    if orient_oracle(a, b, c) > 0 and orient_oracle(a, b, d) < 0:
        if check_acute(a, b, c) and check_acute(b, a, d):
            assert incircle_oracle(a, b, c, d) < 0, (a, b, c, d)


@PROFILE
@given(thales_quad(points_of(moderate)))
def test_two_surely_acute_angles_make_an_edge_locally_delaunay(pts):
    check_edge_certificate(*pts)


@PROFILE
@given(near_cocircular(moderate, st.floats(min_value=2.0**-20, max_value=2.0**20)))
def test_two_surely_acute_angles_nearly_cocircular(pts):
    check_edge_certificate(*pts)


@PROFILE
@given(st.lists(points_of(st.floats(min_value=-1.0, max_value=1.0)), min_size=4, max_size=4))
def test_two_surely_acute_angles_random_quads(pts):
    check_edge_certificate(*pts)


def test_surely_acute_decides_clear_cases():
    # an equilateral triangle's angles are certified; a right angle, an obtuse one and
    # a degenerate triangle's never are
    h = math.sqrt(3) / 2
    assert check_acute((0.0, 0.0), (1.0, 0.0), (0.5, h))
    assert not check_acute((0.0, 0.0), (2.0, 0.0), (1.0, 1.0))
    assert not check_acute((0.0, 0.0), (2.0, 0.0), (1.0, 0.5))
    assert not check_acute((0.0, 0.0), (1.0, 0.0), (0.0, 0.0))
