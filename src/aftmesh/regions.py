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

from ._kernel import orient2d_many

__all__ = ["classify_pieces"]

# Up to this many polygons, each is asked about every probe: a tree over them costs
# more than the few vectorized tests it would save.
FEW_POLYGONS = 8


def classify_pieces(
    polygons: Sequence[shapely.Polygon], probes: np.ndarray, corners: np.ndarray
) -> np.ndarray:
    """The index of the polygon each piece of the CDT lies in (-1: none), from a point
    inside one of its triangles (see Triangulation.components).  The probe is that
    triangle's rounded centroid; for a triangle an ulp or two wide it may fall on an
    edge or outside, and no double may lie inside it at all, so such a piece is
    classified by its exact rational centroid instead (see _exact_inside).

    Many polygons (a tiling of parcels or materials) are asked only about the pieces
    in their bounding box (a tree query), so the cost follows the pieces, not pieces
    times polygons; the tests are the same either way, and so is the answer."""
    geoms = np.empty(len(polygons), dtype=object)
    geoms[:] = polygons
    tree = shapely.STRtree(geoms) if len(polygons) > FEW_POLYGONS else None
    region_of = _first_containing(geoms, tree, probes)
    unsure = _probes_not_inside(probes, corners)
    if len(unsure) == 0:
        return region_of
    rings: dict[int, list[np.ndarray]] = {}
    for c, ks in zip(unsure.tolist(), _candidates(geoms, tree, corners[unsure])):
        region_of[c] = -1
        for k in ks.tolist():
            if k not in rings:
                rings[k] = _ring_coordinates(polygons[k])
            if _exact_inside(rings[k], corners[c]):
                region_of[c] = k
                break
    return region_of


def _candidates(geoms: np.ndarray, tree, corners: np.ndarray) -> list[np.ndarray]:
    """For each triangle (corners), the polygons whose bounding box holds its box, in
    increasing order: the only ones that may hold its centroid."""
    lo, hi = corners.min(axis=1), corners.max(axis=1)
    if tree is None:
        at = np.repeat(np.arange(len(corners)), len(geoms))
        k = np.tile(np.arange(len(geoms)), len(corners))
    else:
        at, k = tree.query(shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]))
        order = np.lexsort((k, at))  # by triangle, then polygon
        at, k = at[order], k[order]
    b = shapely.bounds(geoms)[k]
    fits = (lo[at, 0] >= b[:, 0]) & (lo[at, 1] >= b[:, 1])
    fits &= (hi[at, 0] <= b[:, 2]) & (hi[at, 1] <= b[:, 3])
    at, k = at[fits], k[fits]
    return np.split(k, np.searchsorted(at, np.arange(1, len(corners))))


def _ring_coordinates(poly) -> list[np.ndarray]:
    """The closed rings of every part of the polygon, as (n, 2) arrays."""
    return [
        np.asarray(ring.coords)[:, :2]
        for part in shapely.get_parts(poly)
        for ring in [part.exterior, *part.interiors]
    ]


def _probes_not_inside(probes: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """The pieces whose probe is not strictly inside its triangle: the triangle is
    flat, or the probe is not on the inner side of each edge (exact orient2d, all the
    pieces in one kernel call)."""
    n = len(probes)
    if n == 0:
        return np.zeros(0, dtype=np.intp)
    pts = np.ascontiguousarray(np.concatenate([corners.reshape(-1, 2), probes]), dtype=np.float64)
    a = 3 * np.arange(n, dtype=np.int32)
    b, c, p = a + 1, a + 2, np.arange(n, dtype=np.int32) + 3 * n
    # the triangle (a, b, c), then each edge with the probe: 4 blocks of n rows
    rows = np.empty((4, n, 3), dtype=np.int32)
    rows[:, :, 0] = (a, a, b, c)
    rows[:, :, 1] = (b, b, c, a)
    rows[:, :, 2] = (c, p, p, p)
    side = orient2d_many(pts, rows.reshape(4 * n, 3)).reshape(4, n)
    inside = (side[0] != 0) & (side[1] == side[0]) & (side[2] == side[0]) & (side[3] == side[0])
    return np.flatnonzero(~inside)


def _first_containing(geoms: np.ndarray, tree, probes: np.ndarray) -> np.ndarray:
    """The first polygon (lowest index) whose interior holds each probe, -1 for none;
    with a tree over the polygons, each is asked only about the probes in its box."""
    region_of = np.full(len(probes), -1, dtype=np.int32)
    if tree is None:
        for k, poly in enumerate(geoms):
            inside = shapely.contains_xy(poly, probes[:, 0], probes[:, 1])
            region_of[inside & (region_of < 0)] = k
        return region_of
    at, k = tree.query(shapely.points(probes))
    inside = shapely.contains_xy(geoms[k], probes[at, 0], probes[at, 1])
    first = np.full(len(probes), len(geoms), dtype=np.int64)
    np.minimum.at(first, at[inside], k[inside])
    held = first < len(geoms)
    region_of[held] = first[held]
    return region_of


def _exact_inside(rings: list[np.ndarray], corners: np.ndarray) -> bool:
    """Whether the exact centroid of the triangle `corners` is inside the polygon of
    these closed rings (even-odd rule over all of them, in rational arithmetic where
    floats could err).  The centroid is strictly inside a triangle of the CDT, so it
    is on no ring."""
    px = sum((Fraction(float(v)) for v in corners[:, 0]), Fraction(0)) / 3
    py = sum((Fraction(float(v)) for v in corners[:, 1]), Fraction(0)) / 3
    px_near = float(px)  # the nearest double (see _above)
    inside = False
    for c in rings:
        above = _above(c[:, 1], py)
        for k in np.flatnonzero(above[:-1] != above[1:]).tolist():
            (xa, ya), (xb, yb) = c[k].tolist(), c[k + 1].tolist()
            # the edge meets the line y = py between its ends' x: an edge wholly on
            # one side of px's rounding interval needs no rational crossing point
            if min(xa, xb) > px_near:
                inside = not inside
                continue
            if max(xa, xb) < px_near:
                continue
            x = Fraction(xa) + (py - Fraction(ya)) * (Fraction(xb) - Fraction(xa)) / (
                Fraction(yb) - Fraction(ya)
            )
            if px < x:
                inside = not inside
    return inside


def _above(y: np.ndarray, py: Fraction) -> np.ndarray:
    """y > py for each double y, exactly.  The double nearest py decides every y but
    itself: a double above it is above py's rounding interval, one below it below."""
    nearest = float(py)  # Fraction's float is correctly rounded
    above = y > nearest
    for k in np.flatnonzero(y == nearest).tolist():
        above[k] = Fraction(float(y[k])) > py
    return above
