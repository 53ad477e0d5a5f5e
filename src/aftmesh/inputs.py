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

from itertools import combinations
from os import PathLike

import numpy as np
import shapely
from shapely.geometry import (
    GeometryCollection,
    MultiPolygon,
    Polygon,
)

from ._kernel import coordinate_problems, ring_chains, rings_proved_valid
from ._typing import DomainArg
from .domain_record import Domain
from .errors import InvalidDomainError
from .noding import merge_and_node
from .pslg import MAX_COORDINATE, MIN_COORDINATE, check_range
from .pslg_input import from_dict, from_poly_file
from .repair import repair_domain
from .validity import MANY_POLYGONS, check_lines_inside, check_polygon, check_polygons

__all__ = ["Domain", "to_domain"]

# Two regions overlap when their common area exceeds this fraction of the smaller
# one: below it the overlap is the rounding of a shared boundary, not a real overlap.
REGION_OVERLAP = 1e-12
# Up to this many polygons, their rings are taken one polygon at a time: shapely's
# vectorized get_rings costs about 10 us however few there are.
FEW_POLYGONS = 16


def _ring_arrays(polygons: list[Polygon], names: list[str], note: list[str], coords=None):
    """Every ring of the polygons at once (each polygon's exterior ring, then its
    holes): its distinct vertices in order, each with its outgoing input edge.  A run
    of repeated vertices is kept once, as its last copy, whose outgoing edge is the
    one that leaves the run.  Vertices on a straight run of a ring stay: users put
    them there on purpose (a load point, a sensor, where a boundary condition
    changes); near-coincident ones are merged by the tolerance instead.

    The polygons passed check_polygon, so each ring has at least three distinct
    vertices.  Returns (vertices, segments, input edge of each segment, ring of each
    input edge, midpoint of each input edge, ring names); a ring of n vertices
    (closing one not counted) has n input edges, numbered on from the ring before."""
    if (
        coords is not None
        and len(polygons) == 1
        and not shapely.get_num_interior_rings(polygons[0])
    ):
        # a lone polygon without holes: its coordinates are its one ring's
        ring_of, holes = np.zeros(len(coords), dtype=np.int64), [0]
    else:
        rings, holes = _rings(polygons)
        coords, ring_of = shapely.get_coordinates(rings, return_index=True)
    n_rings = len(holes) + sum(holes)
    pts, segs, edge, mid, ring, removed = ring_chains(
        coords, ring_of.astype(np.int64, copy=False), n_rings
    )
    ring_names = _ring_names(names, holes)
    # each ring keeps its coordinates but the closing one and its repeats (ints: a
    # numpy call costs more than this on a small polygon)
    if len(pts) != len(coords) - n_rings:
        for r in np.flatnonzero(removed).tolist():
            note.append(f"{ring_names[r]}: removed {int(removed[r])} repeated vertices")
    return pts, segs, edge, ring, mid, ring_names


def _rings(polygons: list[Polygon]) -> tuple[list | np.ndarray, list[int]]:
    """Each polygon's exterior ring then its holes, and the number of holes of each."""
    if len(polygons) <= FEW_POLYGONS:
        rings: list = []
        holes = []
        for p in polygons:
            inner = list(p.interiors)
            rings.append(p.exterior)
            rings.extend(inner)
            holes.append(len(inner))
        return rings, holes
    n_holes = shapely.get_num_interior_rings(polygons)
    # get_rings is several times slower than taking the exterior rings when that is all
    if n_holes.any():
        return shapely.get_rings(polygons), n_holes.tolist()
    return shapely.get_exterior_ring(polygons), n_holes.tolist()


def _ring_names(names: list[str], holes: list[int]) -> list[str]:
    out = []
    for name, n in zip(names, holes):
        out.append(f"{name}, exterior ring")
        out.extend(f"{name}, hole {i}" for i in range(n))
    return out


def _with_lines(rings: tuple, lines: list, line_names: list[str], points: list):
    """The rings' arrays (see _ring_arrays) with the constraint lines' vertices,
    segments and input edges appended, then the fixed points' vertices."""
    verts, segs, edges, source, mids, names = rings
    names = list(names)
    if not lines and not points:
        return verts, segs, edges, source, mids, names
    if lines:
        line = _line_arrays(lines, len(verts), len(mids), len(names))
        verts, segs, edges, source, mids = (
            np.concatenate([a, b]) for a, b in zip((verts, segs, edges, source, mids), line)
        )
        names.extend(line_names)
    if points:
        verts = np.concatenate([verts, shapely.get_coordinates(points)])
    return verts, segs, edges, source, mids, names


def _line_arrays(lines: list, n_vertices: int, n_edges: int, n_sources: int):
    """All constraint lines at once, numbered on from the rings' n_vertices vertices,
    n_edges input edges and n_sources sources: their vertices (a run of repeated
    vertices kept once, as its last copy, so each keeps the input edge that leaves
    the run, as in a ring; a line whose vertices are all at one place is a fixed
    point), segments, the input edge of each segment, the source of each input edge
    and each input edge's midpoint."""
    coords, line_of = shapely.get_coordinates(lines, return_index=True)
    per_line = np.bincount(line_of, minlength=len(lines))
    first = np.zeros(len(lines) + 1, dtype=np.int64)
    first[1:] = np.cumsum(per_line)
    last = np.zeros(len(coords), dtype=bool)
    last[first[1:][per_line > 0] - 1] = True  # a line's last coordinate
    keep = last.copy()
    keep[:-1] |= (coords[:-1] != coords[1:]).any(axis=1)
    inner = ~last[:-1]  # pairs of consecutive coordinates of one line: its input edges
    mids = (0.5 * (coords[:-1] + coords[1:]))[inner]
    n_line_edges = np.maximum(per_line - 1, 0)
    source = np.repeat(np.arange(len(lines), dtype=np.int64) + n_sources, n_line_edges)
    edge_base = np.zeros(len(lines), dtype=np.int64)
    edge_base[1:] = np.cumsum(n_line_edges)[:-1]
    kept_line = line_of[keep]
    kept_edge = (np.arange(len(coords)) - first[line_of])[keep] + edge_base[kept_line] + n_edges
    chained = kept_line[:-1] == kept_line[1:]  # consecutive kept vertices of one line
    ids = np.arange(len(kept_line), dtype=np.int64) + n_vertices
    segs = np.c_[ids[:-1], ids[1:]][chained]
    return coords[keep], segs, kept_edge[:-1][chained], source, mids


def _from_shapely(
    polygons: list[Polygon],
    lines: list,
    line_names: list[str],
    points: list,
    names: list[str],
    tolerance: float = 0.0,
    valid: bool = False,
    area: float | None = None,
    coords: np.ndarray | None = None,
) -> Domain:
    """Rings of the polygons, constraint lines and fixed points -> a noded Domain.
    `valid`: the polygons are known valid, one polygon or the parts of a valid
    multipolygon (so their rings cannot cross); `area`: the area of their union;
    `coords`: the coordinates of a lone polygon, if check_polygon has them."""
    note: list[str] = []
    rings = _ring_arrays(polygons, names, note, coords)
    return _noded(rings, note, polygons, lines, line_names, points, tolerance, valid, area)


def _noded(
    rings: tuple,
    note: list[str],
    polygons: list[Polygon],
    lines: list,
    line_names: list[str],
    points: list,
    tolerance: float,
    valid: bool,
    area: float | None,
    apart: bool = False,
    ring_polygon: np.ndarray | None = None,
) -> Domain:
    """_from_shapely's Domain from the rings' arrays (_ring_arrays); `apart`: the
    rings are known to meet nowhere but at common vertices (see merge_and_node),
    ring_polygon: then the polygon of each ring, for the Domain."""
    n_rings = len(rings[5])
    verts, segs, edges, source, mids, source_names = _with_lines(rings, lines, line_names, points)
    edge_source = source.astype(np.int32)
    is_ring = edge_source < n_rings
    report: dict = {}
    valid_rings = 0
    if valid and not lines and not points:
        valid_rings = len(source_names)
    verts, segs, edges = merge_and_node(
        verts, segs, edges, note, is_ring, tolerance, report, valid_rings, apart
    )
    return Domain(
        verts,
        segs.astype(np.int32),
        edges.astype(np.int32),
        edge_source,
        source_names,
        edge_is_ring=is_ring,
        polygons=polygons,
        area=area,
        cleanup=note,
        edge_midpoints=mids,
        report={"tolerance": report} if report else {},
        n_rings=n_rings,
        ring_polygon=ring_polygon,
    )


def proved_polygon(domain: Polygon | MultiPolygon) -> Domain | None:
    """from_geometry(domain) for a lone Polygon or MultiPolygon whose rings the kernel
    proves valid (rings_proved_valid: simple, meeting at most at common vertices where
    none crosses another and a polygon's own touches close no cycle, holes in place,
    parts apart or touching so), without GEOS's validity check, which costs more than
    the rest of the conversion on a small polygon; None when anything is not plainly
    fine (empty, z values, a coordinate not finite or out of range, rings not
    proved), and from_geometry then decides, with its messages.  The Domain is the one
    from_geometry makes."""
    coords = shapely.get_coordinates(domain)
    if (
        len(coords) == 0
        or shapely.get_coordinate_dimension(domain) != 2
        or coordinate_problems(coords, MIN_COORDINATE, MAX_COORDINATE)
    ):
        return None
    if type(domain) is Polygon:
        polygons, names, area = [domain], ["the polygon"], float(domain.area)
    else:
        polygons = list(domain.geoms)
        if len(polygons) == 1:
            return proved_polygon(polygons[0])
        if not (shapely.area(polygons) > 0).all():
            return None
        names = [f"polygon {k}" for k in range(len(polygons))]
        # from_geometry's union of a valid multipolygon's parts is MultiPolygon(parts):
        # this geometry, whose area GEOS sums part by part in the same order
        area = float(domain.area)
        coords = None  # from_geometry reads the rings part by part
    if not area > 0:
        return None
    note: list[str] = []
    rings = _ring_arrays(polygons, names, note, coords)
    ring_polygon = None
    if len(polygons) == 1:  # its rings are all the rings
        first_ring = np.array((0, len(rings[5])), dtype=np.int64)
    else:
        per_polygon = shapely.get_num_interior_rings(polygons) + 1
        first_ring = np.zeros(len(polygons) + 1, dtype=np.int64)
        first_ring[1:] = np.cumsum(per_polygon)
        ring_polygon = np.repeat(np.arange(len(polygons), dtype=np.int32), per_polygon)
    if not rings_proved_valid(rings[0], rings[1], rings[2], rings[3], first_ring):
        return None
    return _noded(
        rings, note, polygons, [], [], [], 0.0, True, area, apart=True, ring_polygon=ring_polygon
    )


# shapely's type ids of the parts a domain may have, by what they become
POLYGON_TYPES = (3, 6)  # Polygon, MultiPolygon
LINE_TYPES = (1, 2, 5)  # LineString, LinearRing, MultiLineString
POINT_TYPES = (0, 4)  # Point, MultiPoint
MULTI_LINE = 5
# what each shapely type id (+ 1: -1 is a missing geometry; 7 a nested collection)
# is to a domain: 0 polygons, 1 lines, 2 points, -1 none of them (np.isin costs
# several microseconds a call)
_PART_KIND = np.full(9, -1, dtype=np.int8)
for _kind, _types in enumerate((POLYGON_TYPES, LINE_TYPES, POINT_TYPES)):
    _PART_KIND[np.array(_types) + 1] = _kind
del _kind, _types


def _split_geometry(domain):
    """A shapely geometry's polygons, constraint lines (with their names) and points.
    A collection's parts are sorted by type all at once, not one by one (a domain
    may carry thousands of lines or points)."""
    if not isinstance(domain, GeometryCollection):
        if isinstance(domain, (Polygon, MultiPolygon)):
            return polygon_parts(domain, "the domain"), [], [], []
        parts = np.empty(1, dtype=object)
        parts[0] = domain
    else:
        parts = shapely.get_parts(domain)
    kinds = shapely.get_type_id(parts)
    part_kind = _PART_KIND[kinds + 1]
    unknown = np.flatnonzero(part_kind < 0)
    if len(unknown):
        raise InvalidDomainError(f"cannot mesh a {parts[unknown[0]].geom_type}")
    polygons = list(shapely.get_parts(parts[part_kind == 0]))
    points = list(shapely.get_parts(parts[part_kind == 2]))
    is_line = part_kind == 1
    lines, owner = shapely.get_parts(parts[is_line], return_index=True)
    count = np.bincount(owner, minlength=int(is_line.sum()))
    start = np.zeros(len(count), dtype=np.int64)
    start[1:] = np.cumsum(count)[:-1]
    # a line's pieces are "part j of constraint line n" only when a MultiLineString
    # has several; n counts the line parts, even one with no piece
    plain = (count == 1) | (kinds[is_line] != MULTI_LINE)
    line_names = [
        f"constraint line {n}" if plain[n] else f"part {j} of constraint line {n}"
        for n, j in zip(owner.tolist(), (np.arange(len(lines)) - start[owner]).tolist())
    ]
    return polygons, list(lines), line_names, points


def from_geometry(domain: shapely.Geometry, tolerance: float = 0.0) -> Domain:
    """A shapely Polygon / MultiPolygon / GeometryCollection (its lines and points
    are internal constraints)."""
    polygons, lines, line_names, points = _split_geometry(domain)
    if not polygons:
        raise InvalidDomainError("the domain has no polygon to mesh")
    names = [f"polygon {k}" if len(polygons) > 1 else "the polygon" for k in range(len(polygons))]
    # parts that meet at points only (a valid multipolygon, whose parts are then valid
    # each): their union (an overlay, ten times the cost of this check on real data)
    # is those parts again, and only its area is used
    multi = MultiPolygon(polygons) if len(polygons) > 1 and not lines and not points else None
    parts_valid = multi is not None and bool(shapely.is_valid(multi))
    checked = check_polygons(polygons, names, parts_valid)
    # the union of one polygon is that polygon, vertex for vertex (GEOS returns a
    # copy), so it is not computed: check_polygon's validity holds for what is meshed
    valid = len(polygons) == 1 or parts_valid
    if len(polygons) == 1:
        union = polygons[0]
    elif parts_valid:
        union = multi
    else:
        union = shapely.union_all(polygons)
    check_lines_inside(polygons, lines, line_names, points, tolerance, union)
    coords = None
    if len(checked) == 1:  # the union is the polygon: its coordinates and area are known
        coords, area = checked[0][0], float(checked[0][1])
    else:
        area = float(union.area)
    if isinstance(union, Polygon):
        polygons, names = [union], ["the polygon"]
    return _from_shapely(polygons, lines, line_names, points, names, tolerance, valid, area, coords)


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
    return _from_shapely(
        [poly], [], [], [], ["the polygon"], tolerance, valid=True, area=float(poly.area)
    )


def _region_polygon(k: int, item):
    if isinstance(item, shapely.Geometry):
        return item
    if is_coordinate_array(item):
        try:
            return Polygon(np.asarray(item, dtype=np.float64))
        except (ValueError, TypeError) as exc:
            raise InvalidDomainError(f"region {k} is not a polygon ring: {exc}") from None
    raise InvalidDomainError(f"region {k} is a {type(item).__name__}, expected a polygon")


def first_overlap(polygons: list) -> tuple[int, int, float] | None:
    """The first pair of regions i < j (ordered by i, then j) whose common area is
    more than REGION_OVERLAP of the smaller one's, with that area; None if none.  Only
    regions whose bounding boxes meet can share area, so only those pairs are looked
    at (a tree query): a tiling of k regions costs about 8 k relations, not k^2 / 2
    intersections."""
    if len(polygons) < 2:
        return None
    geoms = np.empty(len(polygons), dtype=object)
    geoms[:] = polygons
    if len(polygons) <= MANY_POLYGONS:
        # every pair i < j, by i then j (np.triu_indices's order, at a third of its
        # cost on a few polygons)
        pairs = np.array(list(combinations(range(len(polygons)), 2)), dtype=np.intp)
        i, j = pairs[:, 0], pairs[:, 1]
    else:
        i, j = shapely.STRtree(geoms).query(geoms)
        pairs = i < j
        i, j = i[pairs], j[pairs]
    # interiors that do not meet share no area: only the others are intersected (the
    # relation costs about a third of the intersection, and most neighbours only touch)
    meet = shapely.relate_pattern(geoms[i], geoms[j], "T********")
    i, j = i[meet], j[meet]
    order = np.lexsort((j, i))
    i, j = i[order], j[order]
    overlap = shapely.area(shapely.intersection(geoms[i], geoms[j]))
    areas = shapely.area(geoms)
    bad = np.flatnonzero(overlap > REGION_OVERLAP * np.minimum(areas[i], areas[j]))
    if len(bad) == 0:
        return None
    k = bad[0]
    return int(i[k]), int(j[k]), float(overlap[k])


def from_regions(items: list, tolerance: float = 0.0) -> Domain:
    """A sequence of polygons with disjoint interiors: one region each."""
    if not items:
        raise InvalidDomainError("the domain is an empty sequence")
    polygons: list = []
    flat: list[Polygon] = []
    names: list[str] = []
    for k, item in enumerate(items):
        try:
            poly = _region_polygon(k, item)
            parts = polygon_parts(poly, f"region {k}")
        except InvalidDomainError:
            check_polygons(flat, names)  # an earlier region's problem is named first
            raise
        polygons.append(poly)
        flat += parts
        names += [f"region {k}"] * len(parts)
    check_polygons(flat, names)
    found = first_overlap(polygons)
    if found is not None:
        i, j, overlap = found
        raise InvalidDomainError(
            f"regions {i} and {j} overlap (common area {overlap:.6g}): regions must "
            "have disjoint interiors"
        )
    dom = _from_shapely(
        flat, [], [], [], names, tolerance, area=float(sum(p.area for p in polygons))
    )
    dom.polygons = polygons
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
    if type(domain) in (Polygon, MultiPolygon) and not repair and not tolerance > 0:
        proved = proved_polygon(domain)
        if proved is not None:
            return proved
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
