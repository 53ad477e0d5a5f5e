"""Input adapters: each accepted domain form -> a :class:`Domain`.

One function per form (see :func:`to_domain`); each validates its input with messages
naming the ring, region, line or segment at fault, cleans up the rings, numbers the
input edges, and hands the edges to :mod:`aftmesh.noding`.

Input edges are numbered as the user drew them (``Mesh.segment_sources``): for shapely
input, polygon by polygon, each polygon's exterior ring then its holes, each ring's
edges in coordinate order (edge i from coords[i] to coords[i + 1]), then the
constraint lines' edges in order; for a dict or ``.poly`` file, the index in its
``segments``; for an (n, 2) ring, edge i from vertex i to vertex i + 1.
"""

from __future__ import annotations

from os import PathLike

import numpy as np
import shapely
from shapely.geometry import (
    GeometryCollection,
    LineString,
    MultiLineString,
    MultiPoint,
    MultiPolygon,
    Point,
    Polygon,
)

from ._typing import DomainArg
from .domain_record import Domain
from .errors import InvalidDomainError
from .noding import merge_and_node
from .pslg import check_range
from .pslg_input import from_dict, from_poly_file
from .repair import repair_domain
from .validity import check_lines_inside, check_polygon

__all__ = ["Domain", "to_domain"]

# Two regions overlap when their common area exceeds this fraction of the smaller
# one: below it the overlap is the rounding of a shared boundary, not a real overlap.
REGION_OVERLAP = 1e-12


class _Chains:
    """Rings and lines gathered as vertices and numbered input edges."""

    def __init__(self):
        self.vertices: list[np.ndarray] = []
        self.segments: list[np.ndarray] = []
        self.edge_ids: list[np.ndarray] = []
        self.edge_source: list[np.ndarray] = []
        self.midpoints: list[np.ndarray] = []
        self.names: list[str] = []
        self.is_ring: list[bool] = []
        self.n_vertices = 0
        self.n_edges = 0

    def add(
        self,
        coords: np.ndarray,
        edge_ids: np.ndarray,
        n_edges: int,
        closed: bool,
        name: str,
        midpoints: np.ndarray,
    ) -> None:
        """Add one ring or line: `coords` cleaned, `edge_ids[i]` the input edge (within
        this chain, of `n_edges`) from coords[i] to the next vertex."""
        n = len(coords)
        source = len(self.names)
        self.names.append(name)
        self.is_ring.append(closed)
        self.edge_source.append(np.full(n_edges, source))
        self.midpoints.append(midpoints)
        if n >= 2:
            idx = np.arange(n)
            seg = np.c_[idx, (idx + 1) % n] if closed else np.c_[idx[:-1], idx[1:]]
            self.vertices.append(coords)
            self.segments.append(seg + self.n_vertices)
            self.edge_ids.append(np.asarray(edge_ids[: len(seg)]) + self.n_edges)
            self.n_vertices += n
        self.n_edges += n_edges

    def add_points(self, pts: np.ndarray) -> None:
        self.vertices.append(pts)
        self.n_vertices += len(pts)


def _ring_chain(coords: np.ndarray, note: list[str], name: str):
    """A ring's distinct vertices in order, each with the index of its outgoing input
    edge: a run of repeated vertices is kept once, as its last copy, whose outgoing
    edge is the one that leaves the run.  Vertices on a straight run of the ring stay:
    users put them there on purpose (a load point, a sensor, where a boundary
    condition changes); near-coincident ones are merged by the tolerance instead."""
    c = np.asarray(coords, dtype=np.float64)
    closed = len(c) > 1 and (c[0] == c[-1]).all()
    n = len(c) - 1 if closed else len(c)
    open_c = c[:n]
    keep = (open_c != np.roll(open_c, -1, axis=0)).any(axis=1) if n > 1 else np.ones(n, bool)
    if n > 1 and not keep.any():
        keep[-1] = True
    if int(n - keep.sum()):
        note.append(f"{name}: removed {int(n - keep.sum())} repeated vertices")
    ids = np.flatnonzero(keep)
    mid = 0.5 * (open_c + np.roll(open_c, -1, axis=0))
    return open_c[keep], ids, n, mid


def _line_chain(coords: np.ndarray):
    """A line's distinct vertices, each with the index of its outgoing input edge."""
    c = np.asarray(coords, dtype=np.float64)
    keep = np.ones(len(c), dtype=bool)
    keep[:-1] = (c[:-1] != c[1:]).any(axis=1)
    mid = 0.5 * (c[:-1] + c[1:])
    return c[keep], np.flatnonzero(keep), max(len(c) - 1, 0), mid


def _from_shapely(
    polygons: list[Polygon],
    lines: list,
    line_names: list[str],
    points: list,
    names: list[str],
    tolerance: float = 0.0,
    valid: bool = False,
) -> Domain:
    """Rings of the polygons, constraint lines and fixed points -> a noded Domain.
    `valid`: the one polygon is known valid (so its rings cannot cross)."""
    note: list[str] = []
    chains = _Chains()
    for k, poly in enumerate(polygons):
        rings = [("exterior ring", poly.exterior)] + [
            (f"hole {i}", h) for i, h in enumerate(poly.interiors)
        ]
        for rname, ring in rings:
            name = f"{names[k]}, {rname}"
            c, ids, n_edges, mid = _ring_chain(np.asarray(ring.coords)[:, :2], note, name)
            chains.add(c, ids, n_edges, True, name, mid)
    for line, name in zip(lines, line_names):
        c, ids, n_edges, mid = _line_chain(np.asarray(line.coords)[:, :2])
        chains.add(c, ids, n_edges, False, name, mid)
    if points:
        chains.add_points(np.concatenate([np.asarray(p.coords)[:, :2] for p in points]))
    verts = np.concatenate(chains.vertices) if chains.vertices else np.zeros((0, 2))
    segs = np.concatenate(chains.segments) if chains.segments else np.zeros((0, 2), np.int64)
    edges = np.concatenate(chains.edge_ids) if chains.edge_ids else np.zeros(0, np.int64)
    edge_source = (
        np.concatenate(chains.edge_source) if chains.edge_source else np.zeros(0, np.int64)
    ).astype(np.int32)
    is_ring = np.asarray(chains.is_ring, dtype=bool)[edge_source]
    report: dict = {}
    valid_rings = 0
    if valid and len(polygons) == 1 and not lines and not points:
        valid_rings = len(chains.names)
    verts, segs, edges = merge_and_node(
        verts, segs, edges, note, is_ring, tolerance, report, valid_rings
    )
    union_area = float(shapely.union_all(polygons).area)
    mids = np.concatenate(chains.midpoints) if chains.midpoints else np.zeros((0, 2))
    return Domain(
        verts,
        segs.astype(np.int32),
        edges.astype(np.int32),
        edge_source,
        chains.names,
        edge_is_ring=is_ring,
        polygons=polygons,
        area=union_area,
        cleanup=note,
        edge_midpoints=mids,
        report={"tolerance": report} if report else {},
    )


def _split_geometry(domain):
    """A shapely geometry's polygons, constraint lines (with their names) and points."""
    polygons, lines, line_names, points = [], [], [], []
    parts = shapely.get_parts(domain) if isinstance(domain, GeometryCollection) else [domain]
    n_lines = 0
    for part in parts:
        if isinstance(part, (Polygon, MultiPolygon)):
            polygons.extend(polygon_parts(part, "the domain"))
        elif isinstance(part, (LineString, MultiLineString)):
            pieces = list(shapely.get_parts(part))
            for j, piece in enumerate(pieces):
                lines.append(piece)
                line_names.append(
                    f"constraint line {n_lines}"
                    if len(pieces) == 1 or isinstance(part, LineString)
                    else f"part {j} of constraint line {n_lines}"
                )
            n_lines += 1
        elif isinstance(part, (Point, MultiPoint)):
            points.extend(shapely.get_parts(part))
        else:
            raise InvalidDomainError(f"cannot mesh a {part.geom_type}")
    return polygons, lines, line_names, points


def from_geometry(domain: shapely.Geometry, tolerance: float = 0.0) -> Domain:
    """A shapely Polygon / MultiPolygon / GeometryCollection (its lines and points
    are internal constraints)."""
    polygons, lines, line_names, points = _split_geometry(domain)
    if not polygons:
        raise InvalidDomainError("the domain has no polygon to mesh")
    names = [f"polygon {k}" if len(polygons) > 1 else "the polygon" for k in range(len(polygons))]
    for k, p in enumerate(polygons):
        check_polygon(p, names[k])
    check_lines_inside(polygons, lines, line_names, points, tolerance)
    checked = polygons[0] if len(polygons) == 1 else None
    single = shapely.union_all(polygons)
    if isinstance(single, Polygon):
        polygons, names = [single], ["the polygon"]
    # the union of one polygon is that polygon, vertex for vertex, in practice: then
    # check_polygon's validity holds for what is meshed
    valid = checked is not None and bool(shapely.equals_exact(polygons[0], checked, 0.0))
    return _from_shapely(polygons, lines, line_names, points, names, tolerance, valid)


def from_ring(arr: np.ndarray, tolerance: float = 0.0) -> Domain:
    """An (n, 2) array of coordinates: one polygon ring."""
    bad = ~np.isfinite(arr).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InvalidDomainError(f"vertex {i} = {arr[i].tolist()} is not finite")
    if len(arr) < 3:
        raise InvalidDomainError(f"a polygon ring needs at least 3 vertices, got {len(arr)}")
    try:
        poly = Polygon(arr)
    except (ValueError, TypeError) as exc:
        raise InvalidDomainError(f"the ring is not a polygon: {exc}") from None
    check_polygon(poly, "the polygon")
    return _from_shapely([poly], [], [], [], ["the polygon"], tolerance, valid=True)


def _region_polygon(k: int, item):
    if isinstance(item, shapely.Geometry):
        return item
    if is_coordinate_array(item):
        try:
            return Polygon(np.asarray(item, dtype=np.float64))
        except (ValueError, TypeError) as exc:
            raise InvalidDomainError(f"region {k} is not a polygon ring: {exc}") from None
    raise InvalidDomainError(f"region {k} is a {type(item).__name__}, expected a polygon")


def from_regions(items: list, tolerance: float = 0.0) -> Domain:
    """A sequence of polygons with disjoint interiors: one region each."""
    if not items:
        raise InvalidDomainError("the domain is an empty sequence")
    polygons = []
    for k, item in enumerate(items):
        poly = _region_polygon(k, item)
        for part in polygon_parts(poly, f"region {k}"):
            check_polygon(part, f"region {k}")
        polygons.append(poly)
    for i in range(len(polygons)):
        for j in range(i + 1, len(polygons)):
            overlap = polygons[i].intersection(polygons[j]).area
            if overlap > REGION_OVERLAP * min(polygons[i].area, polygons[j].area):
                raise InvalidDomainError(
                    f"regions {i} and {j} overlap (common area {overlap:.6g}): regions must "
                    "have disjoint interiors"
                )
    flat: list[Polygon] = []
    names: list[str] = []
    for k, p in enumerate(polygons):
        for part in polygon_parts(p, f"region {k}"):
            flat.append(part)
            names.append(f"region {k}")
    dom = _from_shapely(flat, [], [], [], names, tolerance)
    dom.polygons = polygons
    dom.area = float(sum(p.area for p in polygons))
    return dom


def is_coordinate_array(obj: object) -> bool:
    if isinstance(obj, (str, bytes, dict)) or isinstance(obj, shapely.Geometry):
        return False
    try:
        arr = np.asarray(obj, dtype=np.float64)
    except (TypeError, ValueError):
        return False
    return arr.ndim == 2 and arr.shape[1] == 2


def polygon_parts(geom: shapely.Geometry, where: str) -> list[Polygon]:
    if isinstance(geom, Polygon):
        return [geom]
    if isinstance(geom, MultiPolygon):
        return list(geom.geoms)
    raise InvalidDomainError(f"{where} is a {geom.geom_type}, expected a Polygon")


def to_domain(
    domain: DomainArg,
    *,
    keep_vertices: bool = False,
    tolerance: float = 0.0,
    repair: bool = False,
) -> Domain:
    """Convert any accepted domain form into a :class:`Domain` (see
    :mod:`aftmesh.domain`).  `keep_vertices` keeps a dict's segments unsplit (the CDT
    splits them exactly); `tolerance` merges vertices closer than it and snaps line
    ends onto segments that near (0: exact); `repair` makes invalid polygons valid
    first (see :mod:`aftmesh.repair`).  What these changed is in ``Domain.report``."""
    repaired = None
    if repair:
        domain, repaired = repair_domain(domain, is_coordinate_array(domain))
    dom = _dispatch(domain, keep_vertices, tolerance)
    if len(dom.vertices):
        check_range(dom.vertices, "vertices")
    if repaired is not None:
        dom.report["repair"] = repaired
    return dom


def _dispatch(domain, keep_vertices: bool, tolerance: float) -> Domain:
    if isinstance(domain, (str, PathLike)):
        return from_poly_file(domain, not keep_vertices, tolerance)
    if isinstance(domain, dict):
        return from_dict(domain, not keep_vertices, tolerance)
    if isinstance(domain, shapely.Geometry):
        return from_geometry(domain, tolerance)
    if is_coordinate_array(domain):
        return from_ring(np.asarray(domain, dtype=np.float64), tolerance)
    try:
        items = list(domain)
    except TypeError:
        raise InvalidDomainError(
            f"cannot mesh a {type(domain).__name__}: give a shapely geometry, a sequence of "
            "polygons, an (n, 2) array, a dict or a .poly path"
        ) from None
    return from_regions(items, tolerance)
