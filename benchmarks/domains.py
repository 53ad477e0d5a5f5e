"""Built domains of the real-world group: shapes like the ones users mesh.

Each builder returns a :class:`Built`: a shapely geometry, the target size and, for
graded cases, the size as a numpy callable plus the same formula for Gmsh's MathEval
field.  Randomness is seeded, so every run meshes the same domains.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import LineString, MultiPolygon, Point, Polygon, box

__all__ = ["BUILT", "Built"]

SEED = 20261127  # one seed for every random domain: runs compare like with like
CIRCLE_QUAD_SEGS = 16  # shapely buffer resolution (points per quarter circle)


@dataclass
class Built:
    geometry: object  # shapely Polygon / MultiPolygon
    h: float  # uniform size, or the smallest graded size
    description: str
    size: Callable | None = None  # graded size f(x, y) -> array
    gmsh_size_expr: str | None = None  # the same size for Gmsh's MathEval field


def _diag(geom) -> float:
    x0, y0, x1, y1 = geom.bounds
    return math.hypot(x1 - x0, y1 - y0)


def _blob(rng, cx, cy, r, n=9, wobble=0.3) -> Polygon:
    """A star-shaped irregular ring around (cx, cy) of mean radius r."""
    t = np.sort(rng.uniform(0.0, 2 * math.pi, n))
    rad = r * (1.0 + wobble * rng.uniform(-1.0, 1.0, n))
    return Polygon(np.column_stack([cx + rad * np.cos(t), cy + rad * np.sin(t)]))


def _scatter(rng, region, radii, gap, make):
    """Place shapes of the given radii in region without overlap (gap apart),
    largest first, by rejection; gives up on a shape after 200 tries."""
    placed = []
    x0, y0, x1, y1 = region.bounds
    for r in sorted(radii, reverse=True):
        for _ in range(200):
            cx = rng.uniform(x0 + r + gap, x1 - r - gap)
            cy = rng.uniform(y0 + r + gap, y1 - r - gap)
            shape = make(rng, cx, cy, r)
            if all(shape.distance(p) > gap for p in placed):
                placed.append(shape)
                break
    return placed


# ----------------------------------------------------------------------- builders


def coast() -> Built:
    """A fractal coastline: midpoint displacement of a rough square, 7 levels."""
    rng = np.random.default_rng(SEED)
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    for _level in range(7):
        nxt = np.roll(pts, -1, axis=0)
        mid = 0.5 * (pts + nxt)
        d = nxt - pts
        normal = np.column_stack([-d[:, 1], d[:, 0]])
        mid += normal * rng.uniform(-0.22, 0.22, (len(pts), 1))
        out = np.empty((2 * len(pts), 2))
        out[0::2], out[1::2] = pts, mid
        pts = out
    geom = shapely.make_valid(Polygon(pts))
    if geom.geom_type != "Polygon":
        geom = max(getattr(geom, "geoms", [geom]), key=lambda g: g.area)
    return Built(geom, _diag(geom) / 60, "fractal coastline (midpoint displacement, 7 levels)")


def islands() -> Built:
    """A bay with 40 small irregular islands (holes)."""
    rng = np.random.default_rng(SEED + 1)
    sea = box(0.0, 0.0, 2.0, 1.0)
    isles = _scatter(
        rng, sea, rng.uniform(0.015, 0.05, 40), 0.02, lambda r_, x, y, r: _blob(r_, x, y, r)
    )
    geom = sea.difference(shapely.union_all(isles))
    return Built(geom, _diag(geom) / 80, f"sea 2 x 1 with {len(isles)} small islands as holes")


def archipelago() -> Built:
    """A MultiPolygon of 25 disjoint islands, one with a lake holding an islet."""
    rng = np.random.default_rng(SEED + 2)
    isles = _scatter(
        rng,
        box(0.0, 0.0, 3.0, 2.0),
        rng.uniform(0.05, 0.3, 25),
        0.03,
        lambda r_, x, y, r: _blob(r_, x, y, r, n=14, wobble=0.25),
    )
    big = max(isles, key=lambda g: g.area)
    c = big.centroid
    lake = Point(c.x, c.y).buffer(0.3 * math.sqrt(big.area / math.pi), CIRCLE_QUAD_SEGS)
    islet = Point(c.x, c.y).buffer(0.1 * math.sqrt(big.area / math.pi), CIRCLE_QUAD_SEGS)
    isles[isles.index(big)] = big.difference(lake)
    geom = MultiPolygon([*isles, islet])
    what = f"{len(isles) + 1} disjoint islands, a lake with an islet"
    return Built(geom, _diag(geom) / 100, what)


def river() -> Built:
    """A meandering river 0.06 wide with a tributary, in a 4 x 1.2 valley."""
    x = np.linspace(0.0, 4.0, 200)
    main = LineString(np.column_stack([x, 0.6 + 0.3 * np.sin(2.2 * x)]))
    xt = np.linspace(1.3, 2.2, 60)
    yt = 0.6 + 0.3 * np.sin(2.2 * 1.3) + 0.9 * (xt - 1.3) ** 0.8
    trib = LineString(np.column_stack([xt, yt]))
    water = shapely.union(
        main.buffer(0.03, CIRCLE_QUAD_SEGS, cap_style="flat"),
        trib.buffer(0.02, CIRCLE_QUAD_SEGS, cap_style="flat"),
    )
    geom = water.intersection(box(0.0, 0.0, 4.0, 1.2))
    return Built(geom, 0.012, "meandering river 0.06 wide with a tributary 0.04 wide")


def _naca4(m, p, t, n=120, chord=1.0, x0=0.0, y0=0.0, angle=0.0) -> Polygon:
    """A NACA 4-digit section (closed trailing edge), rotated by angle (degrees,
    nose up positive) about its leading edge and moved to (x0, y0)."""
    beta = np.linspace(0.0, math.pi, n)
    x = 0.5 * (1.0 - np.cos(beta))
    yt = 5 * t * (0.2969 * np.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1036 * x**4)
    if m > 0:
        yc = np.where(
            x < p, m / p**2 * (2 * p * x - x**2), m / (1 - p) ** 2 * (1 - 2 * p + 2 * p * x - x**2)
        )
    else:
        yc = np.zeros_like(x)
    ring = (
        np.concatenate(
            [
                np.column_stack([x[::-1], yc[::-1] + yt[::-1]]),
                np.column_stack([x[1:-1], yc[1:-1] - yt[1:-1]]),
            ]
        )
        * chord
    )
    a = -math.radians(angle)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    return Polygon(ring @ rot.T + [x0, y0])


def airfoil() -> Built:
    """A NACA 2412 at 4 degrees in a 4 x 2 channel, uniform size chord / 60."""
    foil = _naca4(0.02, 0.4, 0.12, angle=4.0)
    geom = box(-1.5, -1.0, 2.5, 1.0).difference(foil)
    return Built(geom, 1.0 / 60, "NACA 2412 at 4 deg in a 4 x 2 channel, h = chord / 60")


HL_H0, HL_SLOPE, HL_HMAX = 0.004, 0.12, 0.15  # high-lift size: fine at the elements


def highlift() -> Built:
    """Slat, main element and flap (30-P-30N-like layout), graded from the main chord."""
    main = _naca4(0.02, 0.4, 0.12, n=160)
    slat = _naca4(0.04, 0.3, 0.10, n=80, chord=0.15, x0=-0.16, y0=-0.045, angle=25.0)
    flap = _naca4(0.03, 0.4, 0.10, n=80, chord=0.3, x0=0.93, y0=-0.04, angle=-30.0)
    elems = shapely.union_all([main, slat, flap])
    geom = box(-2.0, -1.5, 3.0, 1.5).difference(elems)

    def size(x, y):
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        dx = np.maximum(np.maximum(-0.2 - x, x - 1.2), 0.0)
        return np.minimum(HL_H0 + HL_SLOPE * np.sqrt(dx * dx + y * y), HL_HMAX)

    dxe = "Max(Max(-0.2 - x, x - 1.2), 0)"
    expr = f"Min({HL_H0} + {HL_SLOPE} * Sqrt({dxe} * {dxe} + y * y), {HL_HMAX})"
    return Built(
        geom,
        HL_H0,
        "3-element high-lift airfoil (slat, main, flap), graded size",
        size=size,
        gmsh_size_expr=expr,
    )


def gear() -> Built:
    """A 24-tooth spur gear with a hub hole and a keyway."""
    teeth, r_root, r_tip = 24, 0.9, 1.0
    pts = []
    for k in range(teeth):
        a0 = 2 * math.pi * k / teeth
        for frac, r in ((0.0, r_root), (0.15, r_tip), (0.35, r_tip), (0.5, r_root)):
            a = a0 + frac * 2 * math.pi / teeth
            pts.append((r * math.cos(a), r * math.sin(a)))
    hub = Point(0, 0).buffer(0.3, CIRCLE_QUAD_SEGS).union(box(-0.05, 0.25, 0.05, 0.36))
    geom = Polygon(pts).difference(hub)
    for k in range(6):  # lightening holes
        a = 2 * math.pi * k / 6
        geom = geom.difference(
            Point(0.6 * math.cos(a), 0.6 * math.sin(a)).buffer(0.12, CIRCLE_QUAD_SEGS)
        )
    return Built(geom, _diag(geom) / 100, "24-tooth gear, hub with keyway, 6 lightening holes")


def city() -> Built:
    """Streets of a town: 10 x 7 blocks (some merged or cut by a diagonal avenue)."""
    rng = np.random.default_rng(SEED + 3)
    street = 0.03
    blocks = []
    for i in range(10):
        for j in range(7):
            w, hgt = rng.uniform(0.12, 0.2), rng.uniform(0.12, 0.2)
            x, y = i * 0.22 + street, j * 0.22 + street
            blocks.append(box(x, y, x + w, y + hgt))
    avenue = LineString([(0.0, 0.2), (2.2, 1.4)]).buffer(0.025, cap_style="flat")
    built_up = shapely.union_all(blocks).difference(avenue)
    area = box(0.0, 0.0, 10 * 0.22 + street, 7 * 0.22 + street)
    geom = area.difference(built_up)
    return Built(geom, 0.015, "street network of a 10 x 7 block town with a diagonal avenue")


def mixed_holes() -> Built:
    """A plate with 120 round holes, radii from 0.006 to 0.1 (log-uniform)."""
    rng = np.random.default_rng(SEED + 4)
    plate = box(0.0, 0.0, 2.0, 1.0)
    radii = np.exp(rng.uniform(math.log(0.006), math.log(0.1), 120))
    holes = _scatter(
        rng, plate, radii, 0.01, lambda r_, x, y, r: Point(x, y).buffer(r, CIRCLE_QUAD_SEGS)
    )
    geom = plate.difference(shapely.union_all(holes))
    return Built(geom, _diag(geom) / 100, f"plate 2 x 1 with {len(holes)} holes of mixed sizes")


def thin_layer() -> Built:
    """A thin ring (thickness 0.02, under two sizes) around a disc of radius 1."""
    geom = Point(0, 0).buffer(1.02, 64).difference(Point(0, 0).buffer(1.0, 64))
    return Built(geom, 0.012, "annular shell 0.02 thick, h = 0.012")


def round_plate() -> Built:
    """A disc of radius 1 as a 256-gon, meshed at its edges' own length: the fronts
    from the whole circle contract, so every ring of the mesh must lose points."""
    sides = 256
    geom = Point(0, 0).buffer(1.0, sides // 4)
    return Built(geom, 2.0 * math.sin(math.pi / sides), "disc as a 256-gon, h = its edge")


GP_H0, GP_SLOPE, GP_HMAX = 0.002, 0.15, 0.04  # graded from a point


def graded_point() -> Built:
    """A unit square with a hole, size graded from a corner point (a singularity)."""
    geom = box(0.0, 0.0, 1.0, 1.0).difference(Point(0.7, 0.6).buffer(0.15, CIRCLE_QUAD_SEGS))

    def size(x, y):
        r = np.hypot(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        return np.minimum(GP_H0 + GP_SLOPE * r, GP_HMAX)

    expr = f"Min({GP_H0} + {GP_SLOPE} * Sqrt(x * x + y * y), {GP_HMAX})"
    return Built(
        geom,
        GP_H0,
        "unit square with a hole, size graded from the corner (0, 0)",
        size=size,
        gmsh_size_expr=expr,
    )


GC_H0, GC_SLOPE, GC_HMAX = 0.004, 0.3, 0.08  # graded from a curve


def graded_curve() -> Built:
    """A 2 x 1 rectangle, size graded from the wave y = 0.5 + 0.15 sin(2 pi x)."""
    geom = box(0.0, 0.0, 2.0, 1.0)

    def size(x, y):
        x = np.asarray(x, dtype=float)
        d = np.abs(np.asarray(y, dtype=float) - 0.5 - 0.15 * np.sin(2 * math.pi * x))
        return np.minimum(GC_H0 + GC_SLOPE * d, GC_HMAX)

    expr = f"Min({GC_H0} + {GC_SLOPE} * Abs(y - 0.5 - 0.15 * Sin(2 * {math.pi!r} * x)), {GC_HMAX})"
    return Built(
        geom,
        GC_H0,
        "2 x 1 rectangle, size graded from a sine curve",
        size=size,
        gmsh_size_expr=expr,
    )


BUILT = {
    "coast": coast,
    "islands": islands,
    "archipelago": archipelago,
    "river": river,
    "airfoil": airfoil,
    "highlift": highlift,
    "gear": gear,
    "city": city,
    "mixed-holes": mixed_holes,
    "thin-layer": thin_layer,
    "round-plate": round_plate,
    "graded-point": graded_point,
    "graded-curve": graded_curve,
}
