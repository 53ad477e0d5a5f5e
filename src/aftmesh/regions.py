"""Classification of the pieces of a CDT into the user's regions.

The segments cut the triangulated domain into pieces (connected sets of triangles);
each piece lies in exactly one of the user's polygons or in none (then it is not
meshed).  A piece is classified by one point strictly inside one of its triangles.
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction

import numpy as np
import shapely

from ._kernel import py_orient2d

__all__ = ["classify_pieces"]


def classify_pieces(
    polygons: Sequence[shapely.Polygon], probes: np.ndarray, corners: np.ndarray
) -> np.ndarray:
    """The index of the polygon each piece of the CDT lies in (-1: none), from a point
    inside one of its triangles (see Triangulation.components).  The probe is that
    triangle's rounded centroid; for a triangle an ulp or two wide it may fall on an
    edge or outside, and no double may lie inside it at all, so such a piece is
    classified by its exact rational centroid instead (see _exact_inside)."""
    region_of = np.full(len(probes), -1, dtype=np.int32)
    for k, poly in enumerate(polygons):
        inside = shapely.contains_xy(poly, probes[:, 0], probes[:, 1])
        region_of[inside & (region_of < 0)] = k
    # Python floats: the same doubles, without a numpy scalar per coordinate
    for c, (((ax, ay), (bx, by), (cx, cy)), (x, y)) in enumerate(
        zip(corners.tolist(), probes.tolist())
    ):
        side = py_orient2d(ax, ay, bx, by, cx, cy)
        if (
            side != 0
            and py_orient2d(ax, ay, bx, by, x, y) == side
            and py_orient2d(bx, by, cx, cy, x, y) == side
            and py_orient2d(cx, cy, ax, ay, x, y) == side
        ):
            continue  # the probe is strictly inside its triangle
        region_of[c] = -1
        for k, poly in enumerate(polygons):
            if _exact_inside(poly, corners[c]):
                region_of[c] = k
                break
    return region_of


def _exact_inside(poly, corners: np.ndarray) -> bool:
    """Whether the exact centroid of the triangle `corners` is inside `poly` (even-odd
    rule over all its rings, in rational arithmetic).  The centroid is strictly inside
    a triangle of the CDT, so it is on no ring."""
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    x0, y0, x1, y1 = poly.bounds
    if lo[0] < x0 or lo[1] < y0 or hi[0] > x1 or hi[1] > y1:
        return False
    px = sum(Fraction(float(v)) for v in corners[:, 0]) / 3
    py = sum(Fraction(float(v)) for v in corners[:, 1]) / 3
    inside = False
    for part in shapely.get_parts(poly):
        for ring in [part.exterior, *part.interiors]:
            c = np.asarray(ring.coords)[:, :2]
            for (xa, ya), (xb, yb) in zip(c[:-1].tolist(), c[1:].tolist()):
                if (ya > py) != (yb > py):
                    x = Fraction(xa) + (py - Fraction(ya)) * (Fraction(xb) - Fraction(xa)) / (
                        Fraction(yb) - Fraction(ya)
                    )
                    if px < x:
                        inside = not inside
    return inside
