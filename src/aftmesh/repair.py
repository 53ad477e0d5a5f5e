"""``generate(..., repair=True)``: make invalid polygons valid before meshing.

The usual answer to an invalid GIS polygon is ``shapely.make_valid``; its result is a
collection whose polygonal part is the domain, plus zero-width lines and points where
the input folded onto itself (slivers).  Here the polygonal part is kept, the slivers
are dropped, and the user's own constraint lines and points are kept when they lie in
or on the repaired domain.  Everything dropped is reported.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry import GeometryCollection, MultiPolygon, Polygon

from ._typing import DomainArg
from .errors import InvalidDomainError
from .validity import validity_reason

__all__ = ["repair_domain"]


def _where(geom) -> str:
    x, y = shapely.get_coordinates(geom)[0]
    return f"({float(x)!r}, {float(y)!r})"


def _describe(geom) -> str:
    kind = geom.geom_type
    if kind in ("LineString", "MultiLineString", "LinearRing"):
        return f"a zero-width sliver of length {geom.length:.6g} from {_where(geom)}"
    return f"a {kind} at {_where(geom)}"


def _polygonal(geom, name: str, report: dict):
    """The polygonal part of make_valid(geom) (geom itself if valid); the rest of
    it is recorded in report['dropped']."""
    if geom.is_valid:
        return geom
    report["repaired"].append(f"{name}: {validity_reason(geom)}")
    fixed = shapely.make_valid(geom)
    polys = []
    for part in shapely.get_parts(fixed):
        if isinstance(part, (Polygon, MultiPolygon)):
            polys.extend(shapely.get_parts(part))
        elif not part.is_empty:
            report["dropped"].append(f"{name}: {_describe(part)}")
    if not polys:
        raise InvalidDomainError(f"{name} has no area left once made valid")
    return polys[0] if len(polys) == 1 else MultiPolygon(polys)


def _repair_collection(domain, report: dict):
    parts = shapely.get_parts(domain) if isinstance(domain, GeometryCollection) else [domain]
    polygons: list = []
    others: list = []
    for part in parts:
        (polygons if isinstance(part, (Polygon, MultiPolygon)) else others).append(part)
    named = [
        (p, f"polygon {k}" if len(polygons) > 1 else "the polygon") for k, p in enumerate(polygons)
    ]
    polygons = [_polygonal(p, name, report) for p, name in named]
    if not polygons:
        return domain  # nothing to repair; the adapter says what is missing
    union = shapely.union_all(polygons)
    kept = []
    for g in others:
        if union.covers(g):
            kept.append(g)
        else:
            report["dropped"].append(
                f"a constraint {g.geom_type} at {_where(g)}: not in or on the repaired domain"
            )
    return (
        GeometryCollection([*polygons, *kept])
        if kept
        else (polygons[0] if len(polygons) == 1 else GeometryCollection(polygons))
    )


def repair_domain(domain: DomainArg, is_ring: bool) -> tuple[DomainArg, dict]:
    """(repaired domain, report) for shapely input, an (n, 2) ring or a sequence of
    polygons; other forms (dict, ``.poly``) are returned as they are with an empty
    report: their segments are not polygons to repair."""
    report: dict = {"repaired": [], "dropped": []}
    if isinstance(domain, shapely.Geometry):
        return _repair_collection(domain, report), report
    if is_ring:
        return _repair_ring(domain, "the polygon", report), report
    if isinstance(domain, (str, bytes, dict)) or not hasattr(domain, "__iter__"):
        return domain, report
    items = []
    for k, item in enumerate(domain):
        if isinstance(item, shapely.Geometry):
            items.append(_polygonal(item, f"region {k}", report))
        else:
            items.append(_repair_ring(item, f"region {k}", report))
    return items, report


def _repair_ring(coords, name: str, report: dict):
    """A ring given as coordinates, made valid; left as it is when it is not even a
    ring of finite numbers (the adapter then says what is wrong with it)."""
    try:
        arr = np.asarray(coords, dtype=np.float64)
        if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 3 or not np.isfinite(arr).all():
            return coords
        ring = Polygon(arr)
    except (TypeError, ValueError):
        return coords
    return _polygonal(ring, name, report)
