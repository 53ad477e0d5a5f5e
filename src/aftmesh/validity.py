"""Validation of shapely input, with messages that name the ring or line at fault and
where it goes wrong.

Real GIS data is often invalid in more than one way at once (a self-touching exterior
and two overlapping holes); the messages list each problem with its own place, so the
user can find it without a GIS at hand.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import numpy as np
import shapely
from shapely.geometry import Polygon

from ._kernel import coordinate_problems
from .errors import InvalidDomainError
from .noding import snap_tolerance
from .pslg import COORDINATE_NOT_FINITE, MAX_COORDINATE, MIN_COORDINATE

__all__ = ["check_lines_inside", "check_polygon", "check_polygons"]

# Above this many polygons (regions, a multipolygon's parts), they are checked all at
# once and their overlaps looked for with a tree; below it, one by one and pair by
# pair cost less than the vectorized calls' own setup.
MANY_POLYGONS = 8

_WHERE = re.compile(r"\[([-+0-9.eEinfa]+) ([-+0-9.eEinfa]+)\]")


def _xy(x, y) -> str:
    return f"({float(x)!r}, {float(y)!r})"


def validity_reason(geom: shapely.Geometry) -> str:
    """shapely's validity reason, with its location written as (x, y)."""
    reason = shapely.is_valid_reason(geom)
    return _WHERE.sub(lambda m: " at " + _xy(m.group(1), m.group(2)), reason)


def _check_finite(poly: Polygon, where: str, coords: np.ndarray) -> None:
    # one vectorized look at x and y (coords) first; the rings one by one (and z) only
    # when that finds a problem or there is more than x and y to look at
    # (one call for has_z and has_m: 3 or 4 ordinates when either is there)
    if shapely.get_coordinate_dimension(poly) == 2 and not (
        coordinate_problems(coords, MIN_COORDINATE, MAX_COORDINATE) & COORDINATE_NOT_FINITE
    ):
        return
    for k, ring in enumerate([poly.exterior, *poly.interiors]):
        c = np.asarray(ring.coords)
        bad = ~np.isfinite(c).all(axis=1)
        if bad.any():
            name = "exterior ring" if k == 0 else f"hole {k - 1}"
            i = int(np.flatnonzero(bad)[0])
            raise InvalidDomainError(f"{where}, {name}: vertex {i} = {c[i].tolist()} is not finite")


def _hole_problems(poly: Polygon) -> list[str]:
    """Holes that are invalid alone, overlap another hole, or leave the exterior."""
    problems = []
    outer = Polygon(poly.exterior)
    holes = [Polygon(h) for h in poly.interiors]
    for k, hole in enumerate(holes):
        if not hole.is_valid:
            problems.append(f"hole {k}: {validity_reason(hole)}")
        elif outer.is_valid and not outer.contains(hole):
            p = hole.difference(outer).representative_point()
            problems.append(f"hole {k} is not inside the exterior ring (at {_xy(*p.coords[0])})")
    valid = np.array([h for h in holes if h.is_valid], dtype=object)
    if len(valid) < 2:
        return problems
    tree = shapely.STRtree(valid)
    index = [k for k, h in enumerate(holes) if h.is_valid]
    for i, j in tree.query(valid, predicate="intersects").T.tolist():
        if i >= j:
            continue
        common = valid[i].intersection(valid[j])
        if common.area > 0:
            problems.append(
                f"holes {index[i]} and {index[j]} overlap at "
                f"{_xy(*common.representative_point().coords[0])}"
            )
        elif common.geom_type != "Point":
            p = shapely.get_coordinates(common)[0]
            problems.append(
                f"holes {index[i]} and {index[j]} touch along a line or at "
                f"more than one point, at {_xy(*p)}"
            )
    return problems


def check_polygon(poly: Polygon, where: str, known_valid: bool = False) -> tuple[np.ndarray, float]:
    """Refuse an empty, non-finite, invalid or zero-area polygon, naming each ring at
    fault (exterior, hole k, holes i and j) and where.  Returns what it looked at: the
    x, y coordinates (each ring closed, the exterior first) and the area.
    `known_valid`: the caller has found it valid already (a valid multipolygon's
    parts are), so its validity is not computed again."""
    coords = shapely.get_coordinates(poly)
    if len(coords) == 0:  # a polygon is empty exactly when it has no coordinates
        raise InvalidDomainError(f"{where} is empty")
    _check_finite(poly, where, coords)
    if not known_valid and not poly.is_valid:
        problems = []
        outer = Polygon(poly.exterior)
        if not outer.is_valid:
            problems.append(f"the exterior ring: {validity_reason(outer)}")
        problems += _hole_problems(poly)
        if not problems:
            problems.append(f"its rings: {validity_reason(poly)}")
        raise InvalidDomainError(f"{where} is not a valid polygon: " + "; ".join(problems))
    area = poly.area
    if not area > 0:
        coords = np.asarray(poly.exterior.coords)
        raise InvalidDomainError(f"{where} has zero area (vertices {coords[:4].tolist()}...)")
    return coords, area


def check_polygons(
    polygons: Sequence[Polygon], names: Sequence[str], known_valid: bool = False
) -> list[tuple[np.ndarray, float]]:
    """check_polygon of each polygon, in order, and their results.  Many polygons are
    first looked at all at once (coordinates, validity unless known, area): when none
    has a problem, none is looked at again and the result is empty; else they are
    checked one by one, so the first problem is named as check_polygon names it."""
    if len(polygons) > MANY_POLYGONS and _plainly_fine(polygons, known_valid):
        return []
    return [check_polygon(p, name, known_valid) for p, name in zip(polygons, names)]


def _plainly_fine(polygons: Sequence[Polygon], known_valid: bool) -> bool:
    """Every polygon passes check_polygon: not empty, x and y only and finite, valid
    (unless known), of positive area (its tests, vectorized)."""
    geoms = np.empty(len(polygons), dtype=object)
    geoms[:] = polygons
    if not (shapely.get_num_coordinates(geoms) > 0).all():
        return False
    if not (shapely.get_coordinate_dimension(geoms) == 2).all():
        return False
    coords = shapely.get_coordinates(geoms)
    if coordinate_problems(coords, MIN_COORDINATE, MAX_COORDINATE) & COORDINATE_NOT_FINITE:
        return False
    if not (known_valid or shapely.is_valid(geoms).all()):
        return False
    return bool((shapely.area(geoms) > 0).all())


def _outside_by_rounding(outside, union, tol: float) -> bool:
    """Whether the parts of a constraint line outside the domain are there only by
    rounding (a line ending on the boundary at a computed point, which the noding
    then puts on the boundary): each part's ends and middle lie within `tol` of the
    domain.  (A straight part whose ends and middle are that near a polygon is that
    near it all along, unless the polygon has a feature right there, which the line
    would then cross, splitting the part.)"""
    parts = [p for p in shapely.get_parts(outside) if not p.is_empty]
    probes = []
    for p in parts:
        c = shapely.get_coordinates(p)
        probes.extend([c[0], c[-1], 0.5 * (c[0] + c[-1])])
    if not probes:
        return True
    return bool((shapely.distance(union, shapely.points(np.array(probes))) <= tol).all())


def _leaves_at(line, union) -> np.ndarray:
    """The first point of `line` (along it) that is outside the domain's interior
    and boundary: where it leaves, or its start if it starts outside."""
    outside = line.difference(union)
    best, best_t = None, np.inf
    for part in shapely.get_parts(outside):
        if part.is_empty:
            continue
        c = shapely.get_coordinates(part)
        t = line.project(shapely.Point(c[0]))
        if t < best_t:
            best, best_t = c[0], t
    return best if best is not None else shapely.get_coordinates(line)[0]


def check_lines_inside(
    polygons: Sequence[Polygon],
    lines: Sequence[shapely.LineString],
    line_names: Sequence[str],
    points: Sequence[shapely.Point],
    tolerance: float = 0.0,
    union: shapely.Geometry | None = None,
) -> None:
    """Refuse constraint lines or fixed points outside the domain (a line may stick
    out by rounding only, see :func:`_outside_by_rounding`, or by `tolerance`).
    `union`: the polygons' union, if the caller has it already."""
    if not lines and not points:
        return
    if union is None:
        union = shapely.union_all(polygons)
    tol = None
    # one vectorized test for all the lines (and points), then the few outside
    outside: list[int] = (
        np.flatnonzero(~shapely.covers(union, list(lines))).tolist() if lines else []
    )
    for k in outside:
        line, name = lines[k], line_names[k]
        if tol is None:
            tol = max(
                tolerance,
                snap_tolerance(
                    np.concatenate([shapely.get_coordinates(g) for g in (*polygons, *lines)])
                ),
            )
        if not _outside_by_rounding(line.difference(union), union, tol):
            p = _leaves_at(line, union)
            raise InvalidDomainError(
                f"{name} is not inside the domain: it leaves the domain at {_xy(*p)}"
            )
    stray: list[int] = (
        np.flatnonzero(~shapely.covers(union, list(points))).tolist() if points else []
    )
    for k in stray:
        p = points[k]
        raise InvalidDomainError(f"fixed point {k} = {list(p.coords)[0]} is not inside the domain")
