"""aftmesh.cdt: the constrained Delaunay triangulation of a PSLG, cross-checked against
Shewchuk's Triangle (the ``triangle`` package) as an independent oracle.

Comparison rules:

* Triangles are compared as sets of sorted vertex triples in *input* numbering (our
  output numbering is mapped back through ``info['vertex_map']``; coincident input
  vertices are identified with the first of them on both sides).
* The CDT is unique exactly when no unconstrained interior edge of it has its four
  vertices cocircular.  We decide that on Triangle's output with exact rational
  arithmetic (below), never from our own output: when Triangle's CDT is unique, the
  triangle sets must be equal; otherwise we check the triangle count, the area, and the
  exact constrained Delaunay property of our mesh.
* The exact checks here use Python integers (every double is an integer times a power
  of two), independently of the kernel's predicates, which ``check_mesh`` relies on.
"""

from __future__ import annotations

import itertools
import os

import numpy as np
import pslg_cases as pc
import pytest
import triangle
from hypothesis import given
from hypothesis import strategies as st
from shapely.geometry import MultiPoint
from triangle.data import get_data_dir

import aftmesh
from aftmesh import _kernel
from aftmesh.checks import check_mesh
from aftmesh.errors import CrossingSegmentsError, InvalidDomainError, InvalidInputError

# --------------------------------------------------------------------------------------
# exact arithmetic, independent of aftmesh
# --------------------------------------------------------------------------------------


def exact_ints(points):
    """The coordinates as Python ints, all scaled by one power of two (exactly)."""
    P = np.asarray(points, dtype=np.float64)
    ratios = [float(v).as_integer_ratio() for v in P.ravel()]
    den = max((d for _, d in ratios), default=1)
    out = np.empty(P.size, dtype=object)
    out[:] = [n * (den // d) for n, d in ratios]
    return out.reshape(P.shape)


def _signs(values):
    return np.array([(v > 0) - (v < 0) for v in values], dtype=np.int64)


def exact_orient(Q, a, b, c):
    """Signs of orient2d for index arrays a, b, c into the exact points Q."""
    A, B, C = Q[a], Q[b], Q[c]
    return _signs(
        (B[:, 0] - A[:, 0]) * (C[:, 1] - A[:, 1]) - (B[:, 1] - A[:, 1]) * (C[:, 0] - A[:, 0])
    )


def exact_incircle(Q, a, b, c, d):
    """Signs of incircle(a, b, c; d): +1 when d is strictly inside the circle through the
    counter-clockwise a, b, c."""
    A, B, C = (Q[i] - Q[d] for i in (a, b, c))
    la = A[:, 0] * A[:, 0] + A[:, 1] * A[:, 1]
    lb = B[:, 0] * B[:, 0] + B[:, 1] * B[:, 1]
    lc = C[:, 0] * C[:, 0] + C[:, 1] * C[:, 1]
    det = (
        la * (B[:, 0] * C[:, 1] - C[:, 0] * B[:, 1])
        + lb * (C[:, 0] * A[:, 1] - A[:, 0] * C[:, 1])
        + lc * (A[:, 0] * B[:, 1] - B[:, 0] * A[:, 1])
    )
    return _signs(det)


def exact_report(points, triangles, constrained):
    """Exact facts about a triangulation given as plain arrays (its own neighbour data
    is not trusted): counts of triangles not strictly CCW, of unconstrained interior
    edges violating the empty-circle test, and of cocircular ones; plus the number of
    edges shared by more than two triangles."""
    T = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    if len(T) == 0:
        return dict(not_ccw=0, non_delaunay=0, cocircular=0, overfull_edges=0)
    Q = exact_ints(points)
    orient = exact_orient(Q, T[:, 0], T[:, 1], T[:, 2])
    cons = {frozenset(map(int, s)) for s in np.asarray(constrained).reshape(-1, 2)}
    owners: dict = {}
    for t, (a, b, c) in enumerate(T.tolist()):
        for u, v, w in ((a, b, c), (b, c, a), (c, a, b)):
            owners.setdefault(frozenset((u, v)), []).append((t, w))
    quads, overfull = [], 0
    for edge, own in owners.items():
        if len(own) > 2:
            overfull += 1
        if len(own) != 2 or edge in cons:
            continue
        (t, _), (_, far) = own
        quads.append((*T[t], far))
    if quads:
        q = np.asarray(quads)
        inc = exact_incircle(Q, q[:, 0], q[:, 1], q[:, 2], q[:, 3])
    else:
        inc = np.zeros(0, dtype=np.int64)
    return dict(
        not_ccw=int((orient <= 0).sum()),
        non_delaunay=int((inc > 0).sum()),
        cocircular=int((inc == 0).sum()),
        overfull_edges=overfull,
    )


def assert_exact_cdt(mesh):
    """Our mesh: every triangle strictly CCW and every unconstrained edge locally
    Delaunay, decided exactly."""
    rep = exact_report(mesh.points, mesh.triangles, mesh.segments)
    assert rep["not_ccw"] == 0, f"{rep['not_ccw']} triangles not strictly CCW (exact)"
    assert rep["non_delaunay"] == 0, f"{rep['non_delaunay']} non-Delaunay edges (exact)"
    assert rep["overfull_edges"] == 0


def exact_area(points, triangles):
    """The total area of the triangles, exactly (a Fraction)."""
    from fractions import Fraction

    T = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    P = np.asarray(points, dtype=np.float64)
    if len(T) == 0:
        return Fraction(0)
    den = max(float(v).as_integer_ratio()[1] for v in P[np.unique(T)].ravel())
    Q = np.empty(P.shape, dtype=object)
    Q[:] = 0
    used = np.unique(T)
    Q[used] = exact_ints(P[used])  # scaled by the same power of two, den
    A, B, C = Q[T[:, 0]], Q[T[:, 1]], Q[T[:, 2]]
    twice = (
        (B[:, 0] - A[:, 0]) * (C[:, 1] - A[:, 1]) - (B[:, 1] - A[:, 1]) * (C[:, 0] - A[:, 0])
    ).sum()
    return Fraction(int(twice), 2 * den * den)


def exact_polygon_area(coords):
    """Shoelace formula, exactly, for a closed ring given without its closing point."""
    from fractions import Fraction

    X = [(Fraction(float(x)), Fraction(float(y))) for x, y in coords]
    return (
        abs(
            sum(
                X[k][0] * X[(k + 1) % len(X)][1] - X[(k + 1) % len(X)][0] * X[k][1]
                for k in range(len(X))
            )
        )
        / 2
    )


def signed_area(points, triangles):
    p = np.asarray(points)[np.asarray(triangles).reshape(-1, 3)]
    return 0.5 * (
        (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
        - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
    )


# --------------------------------------------------------------------------------------
# the oracle comparison
# --------------------------------------------------------------------------------------


def canonical_ids(vertices):
    """For each input vertex, the first input vertex with the same coordinates."""
    first: dict = {}
    return np.array(
        [first.setdefault((x, y), i) for i, (x, y) in enumerate(np.asarray(vertices).tolist())],
        dtype=np.int64,
    )


def output_to_input(mesh, n_in):
    """Our output vertex -> an input vertex mapped to it (checks vertex_map on the way)."""
    vm = np.asarray(mesh.info["vertex_map"])
    assert vm.shape == (n_in,)
    assert ((vm >= -1) & (vm < mesh.n_points)).all()
    back = np.full(mesh.n_points, -1, dtype=np.int64)
    for i, o in enumerate(vm.tolist()):
        if o >= 0 and back[o] < 0:
            back[o] = i
    assert (back >= 0).all(), "an output point is the image of no input vertex"
    return back


def run_triangle(V, S, H, R, convex=False):
    """Triangle on the same PSLG ('p', plus 'c' without segments, 'A' with regions).

    Triangle can crash (segfault) on duplicate vertices referenced by segments, so it
    gets each distinct point once; its output is numbered back into the first input
    vertex of each point."""
    V = np.asarray(V, dtype=np.float64)
    canon = canonical_ids(V)
    keep = np.flatnonzero(canon == np.arange(len(V)))
    new_index = np.full(len(V), -1, dtype=np.int64)
    new_index[keep] = np.arange(len(keep))
    data = dict(vertices=V[keep])
    opts = "pc" if convex else "p"
    if len(S):
        data["segments"] = new_index[canon[np.asarray(S, dtype=np.int64)]].astype(np.int32)
        data["segment_markers"] = (np.arange(len(S)) + 2).astype(np.int32).reshape(-1, 1)
    elif not convex:
        # without segments our domain is the convex hull: Triangle's -c
        opts += "c"
    if len(H):
        data["holes"] = np.asarray(H, dtype=np.float64)
    if len(R):
        R = np.asarray(R, dtype=np.float64)
        data["regions"] = np.c_[R[:, :2], R[:, 2], np.zeros(len(R))]
        opts += "A"
    out = triangle.triangulate(data, opts)
    out.setdefault("triangles", np.zeros((0, 3), dtype=np.int32))
    out.setdefault("segments", np.zeros((0, 2), dtype=np.int32))
    out["added_vertices"] = len(out["vertices"]) - len(keep)
    if out["added_vertices"] == 0:
        # back to input numbering
        out["triangles"] = keep[np.asarray(out["triangles"], dtype=np.int64)].reshape(-1, 3)
        out["segments"] = keep[np.asarray(out["segments"], dtype=np.int64)].reshape(-1, 2)
        out["vertices"] = V
    return out


def _as(a, shape, dtype):
    if a is None:
        return np.zeros((0, shape[1]), dtype=dtype)
    return np.asarray(a, dtype=dtype).reshape(shape)


def cross_check(V, S=None, H=None, R=None, *, area=None, check_cover=False, markers=True):
    """Run aftmesh.cdt and Triangle on the same PSLG and compare.  Returns our mesh and
    whether Triangle's CDT is unique (then the triangle sets were compared)."""
    V = np.asarray(V, dtype=np.float64)
    S = _as(S, (-1, 2), np.int64)
    H = _as(H, (-1, 2), np.float64)
    R = _as(R, (-1, 3), np.float64)
    mesh = aftmesh.cdt(
        V, S if len(S) else None, holes=H if len(H) else None, regions=R if len(R) else None
    )
    check_mesh(mesh, domain_area=area, input_segments=V[S] if (check_cover and len(S)) else None)
    assert_exact_cdt(mesh)

    ref = run_triangle(V, S, H, R)
    assert ref["added_vertices"] == 0, (
        "Triangle added vertices: the test PSLG has crossing segments (test bug)"
    )
    canon = canonical_ids(V)
    back = output_to_input(mesh, len(V))
    # the output points are exactly the input coordinates
    vm = np.asarray(mesh.info["vertex_map"])
    mapped = vm >= 0
    assert np.array_equal(mesh.points[vm[mapped]], V[mapped])
    ours = canon[back[mesh.triangles]] if mesh.n_triangles else np.zeros((0, 3), np.int64)
    theirs = canon[np.asarray(ref["triangles"], dtype=np.int64)]
    ours_set = {tuple(sorted(t)) for t in ours.tolist()}
    theirs_set = {tuple(sorted(t)) for t in theirs.tolist()}
    assert len(ours_set) == mesh.n_triangles

    # the vertices in the domain (used by a triangle) do not depend on the CDT's choice
    used_ours = np.unique(ours)
    used_theirs = np.unique(theirs)
    assert np.array_equal(used_ours, used_theirs), "different vertices kept in the domain"
    # vertex_map is -1 exactly for vertices outside the domain
    assert np.array_equal(np.unique(canon[mapped]), used_theirs)

    # the constrained edges do not depend on the CDT's choice either
    if len(S):
        our_segs = {}
        for (u, v), mk in zip(mesh.segments.tolist(), mesh.segment_markers.tolist()):
            our_segs[frozenset((int(canon[back[u]]), int(canon[back[v]])))] = mk + 2
        their_segs = {}
        for (u, v), mk in zip(
            np.asarray(ref["segments"]).tolist(),
            np.asarray(ref.get("segment_markers", [])).ravel().tolist(),
        ):
            their_segs[frozenset((int(canon[u]), int(canon[v])))] = mk
        assert set(our_segs) == set(their_segs), "different constrained edges"
        assert len(our_segs) == len(mesh.segments), "a segment is listed twice"
        if markers:
            assert our_segs == their_segs, "segment_markers differ from Triangle's"

    ref_rep = exact_report(ref["vertices"], ref["triangles"], ref["segments"])
    assert ref_rep["not_ccw"] == 0 and ref_rep["non_delaunay"] == 0  # sanity of the oracle
    unique = ref_rep["cocircular"] == 0
    if unique:
        missing = sorted(theirs_set - ours_set)[:5]
        extra = sorted(ours_set - theirs_set)[:5]
        assert ours_set == theirs_set, f"triangles differ: missing {missing}, extra {extra}"
    else:
        assert mesh.n_triangles == len(theirs_set)
    # the same domain: exactly the same area (floating-point sums of slivers are not
    # reliable enough for that)
    assert exact_area(mesh.points, mesh.triangles) == exact_area(ref["vertices"], ref["triangles"])
    if area is not None:
        assert mesh.area() == pytest.approx(area, rel=1e-9)

    if len(R):
        attrs = np.asarray(ref["triangle_attributes"]).ravel()
        if unique:
            theirs_reg = {tuple(sorted(t)): int(a) for t, a in zip(theirs.tolist(), attrs)}
            ours_reg = {tuple(sorted(t)): int(r) for t, r in zip(ours.tolist(), mesh.regions)}
            assert ours_reg == theirs_reg, "region markers differ from Triangle's"
        else:
            their_areas = signed_area(ref["vertices"], ref["triangles"])
            our_areas = signed_area(mesh.points, mesh.triangles)
            for mk in set(attrs.astype(int).tolist()) | set(mesh.regions.tolist()):
                assert our_areas[mesh.regions == mk].sum() == pytest.approx(
                    their_areas[attrs.astype(int) == mk].sum(), rel=1e-9, abs=1e-300
                )
    else:
        assert (mesh.regions == 0).all()
    return mesh, unique


def cross_check_case(case, **kw):
    return cross_check(
        case["vertices"], case["segments"], case["holes"], case["regions"], area=case["area"], **kw
    )


# --------------------------------------------------------------------------------------
# 1. random PSLGs in general position against Triangle
# --------------------------------------------------------------------------------------

POINT_KINDS = ["uniform", "gauss", "clusters", "anisotropic", "disk"]
POINT_SIZES = [3, 4, 5, 7, 10, 20, 50, 100, 300, 1000, 2000]


@pytest.mark.parametrize("kind", POINT_KINDS)
def test_random_point_sets_match_triangle(kind):
    rng = np.random.default_rng(POINT_KINDS.index(kind))
    for n in POINT_SIZES:
        for _ in range(2 if n <= 300 else 1):
            case = pc.random_points(rng, n, kind)
            case["area"] = MultiPoint([tuple(p) for p in case["vertices"]]).convex_hull.area
            assert cross_check_case(case)[1], "a random point set is in general position"


@pytest.mark.parametrize("seed", range(100))
def test_box_with_random_segments_matches_triangle(seed):
    rng = np.random.default_rng(1000 + seed)
    n = int(rng.choice([5, 10, 30, 100, 300, 800]))
    m = int(rng.integers(1, n // 2 + 2))
    case = pc.box_with_segments(rng, n, m, k_near=int(rng.choice([4, 12, 40])))
    assert len(case["segments"]) > 4
    assert cross_check_case(case, check_cover=True)[1], "random PSLG in general position"


@pytest.mark.parametrize("seed", range(200))
def test_polygons_with_holes_match_triangle(seed):
    rng = np.random.default_rng(2000 + seed)
    case = pc.polygon_with_holes(rng, n_extra_segments=int(rng.integers(0, 30)))
    assert cross_check_case(case, check_cover=True)[1], "random PSLG in general position"


@pytest.mark.parametrize("seed", range(60))
def test_nested_rings_match_triangle(seed):
    rng = np.random.default_rng(3000 + seed)
    case = pc.nested_rings(rng)
    assert cross_check_case(case, check_cover=True)[1], "random PSLG in general position"


def test_large_polygon_with_holes_matches_triangle():
    rng = np.random.default_rng(7)
    case = pc.polygon_with_holes(
        rng, n_outer=300, n_inner_rings=4, n_points=2000, n_extra_segments=150
    )
    assert cross_check_case(case, check_cover=True)[1], "random PSLG in general position"


# --------------------------------------------------------------------------------------
# Triangle's own sample files
# --------------------------------------------------------------------------------------


def _sample_names():
    names = set()
    for f in os.listdir(get_data_dir()):
        stem, ext = f.rsplit(".", 1)
        if ext in ("node", "poly"):
            names.add(stem)
    return sorted(names)


SAMPLES = _sample_names()


def poly_region_points(name):
    """The (x, y) of the regional attribute rows of a sample .poly file, or None.
    (triangle.get_data misreads rows with both an attribute and an area bound.)"""
    path = os.path.join(get_data_dir(), name + ".poly")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        lines = [ln.split("#")[0].split() for ln in f]
    lines = [ln for ln in lines if ln]
    k = 0
    n_vertices = int(lines[k][0])
    k += 1 + n_vertices
    n_segments = int(lines[k][0])
    k += 1 + n_segments
    n_holes = int(lines[k][0])
    k += 1 + n_holes
    if k >= len(lines) or int(lines[k][0]) == 0:
        return None
    n_regions = int(lines[k][0])
    return np.array([(float(r[1]), float(r[2])) for r in lines[k + 1 : k + 1 + n_regions]])


def test_sample_files_found():
    assert {
        "A",
        "box",
        "double_hex",
        "face",
        "la",
        "square_circle_hole",
        "dots",
        "spiral",
        "greenland",
    } <= set(SAMPLES)


@pytest.mark.parametrize("name", SAMPLES)
def test_triangle_sample_matches_triangle(name):
    d = triangle.get_data(name)
    V = d["vertices"]
    S = d.get("segments")
    H = d.get("holes")
    R = poly_region_points(name)
    if R is not None:
        # our own markers, 1, 2, ... (the files' attributes are floats)
        R = np.c_[R, np.arange(len(R)) + 1]
    if name == "box":
        # its outer boundary is open: with 'p' (no 'c') everything is eaten
        mesh = aftmesh.cdt(V, S, holes=H)
        check_mesh(mesh)
        assert mesh.n_triangles == 0
        assert (
            len(
                triangle.triangulate(dict(vertices=V, segments=S, holes=H), "p").get(
                    "triangles", []
                )
            )
            == 0
        )
        return
    cross_check(V, S, H, R)


# --------------------------------------------------------------------------------------
# 2. cocircular inputs: the CDT is not unique
# --------------------------------------------------------------------------------------


def lattice_circle(r2):
    """All integer points with x^2 + y^2 == r2 (exactly cocircular)."""
    r = int(np.ceil(np.sqrt(r2)))
    return [(x, y) for x in range(-r, r + 1) for y in range(-r, r + 1) if x * x + y * y == r2]


def check_degenerate(V, S=None, H=None, *, area=None):
    """For inputs whose CDT need not be unique: everything cross_check compares (with
    the triangle count and per-region areas instead of the triangle set when Triangle's
    CDT is not unique), and the domain's area."""
    V = np.asarray(V, dtype=np.float64)
    if area is None and S is None:
        area = MultiPoint([tuple(p) for p in V]).convex_hull.area
    return cross_check(V, S, H, None, area=area)


@pytest.mark.parametrize("nx,ny", [(2, 2), (3, 3), (4, 7), (10, 10), (25, 3), (30, 30)])
@pytest.mark.parametrize("scale", [1.0, 0.125, 0.1, 1e-6, 3e5])
def test_grid_points(nx, ny, scale):
    x, y = np.meshgrid(np.arange(nx), np.arange(ny))
    V = np.c_[x.ravel(), y.ravel()] * scale
    mesh, unique = check_degenerate(V)
    # (nx-1)(ny-1) squares, two triangles each, whatever the diagonals
    if scale in (1.0, 0.125):
        assert not unique
        assert mesh.n_triangles == 2 * (nx - 1) * (ny - 1)


@pytest.mark.parametrize("nx,ny", [(4, 4), (6, 4), (12, 12)])
def test_grid_with_boundary_ring_and_square_hole(nx, ny):
    # the grid boundary as segments, and the unit square [1,2]^2 as a hole ring
    idx = -np.ones((ny, nx), dtype=int)
    V = []
    for j in range(ny):
        for i in range(nx):
            idx[j, i] = len(V)
            V.append((i, j))
    ring = (
        [idx[0, i] for i in range(nx)]
        + [idx[j, nx - 1] for j in range(1, ny)]
        + [idx[ny - 1, i] for i in range(nx - 2, -1, -1)]
        + [idx[j, 0] for j in range(ny - 2, 0, -1)]
    )
    S = [(ring[k], ring[(k + 1) % len(ring)]) for k in range(len(ring))]
    S += [
        (idx[1, 1], idx[1, 2]),
        (idx[1, 2], idx[2, 2]),
        (idx[2, 2], idx[2, 1]),
        (idx[2, 1], idx[1, 1]),
    ]
    mesh, unique = check_degenerate(V, S, [(1.5, 1.5)], area=(nx - 1) * (ny - 1) - 1)
    assert not unique
    assert mesh.n_triangles == 2 * ((nx - 1) * (ny - 1) - 1)
    check_mesh(mesh, input_segments=np.asarray(V, float)[np.asarray(S)])


@pytest.mark.parametrize("k", [3, 4, 5, 6, 8, 12, 17, 32, 64, 200])
@pytest.mark.parametrize("with_centre", [False, True])
@pytest.mark.parametrize("with_ring", [False, True])
def test_regular_polygons(k, with_centre, with_ring):
    a = 2 * np.pi * np.arange(k) / k
    V = np.c_[np.cos(a), np.sin(a)]
    if with_centre:
        V = np.vstack([V, [(0.0, 0.0)]])
    S = [(i, (i + 1) % k) for i in range(k)] if with_ring else None
    mesh, _ = check_degenerate(V, S)
    assert mesh.n_triangles == (k if with_centre else k - 2)


@pytest.mark.parametrize("r2", [25, 625, 4225, 5525, 105625])
def test_exactly_cocircular_lattice_points_with_centre(r2):
    pts = lattice_circle(r2)
    assert len(pts) >= 12
    mesh, unique = check_degenerate(pts + [(0, 0)])
    # the centre sees every hull edge: one fan of len(pts) triangles (unique: the
    # centre is inside every circle through three of the others)
    assert unique
    assert mesh.n_triangles == len(pts)
    # and exactly cocircular without the centre: any triangulation of the polygon
    mesh, unique = check_degenerate(pts)
    assert not unique
    assert mesh.n_triangles == len(pts) - 2


def test_concentric_cocircular_rings_of_lattice_points():
    pts = lattice_circle(625) + lattice_circle(25) + lattice_circle(1) + [(0, 0)]
    check_degenerate(pts)
    rng = np.random.default_rng(5)
    perm = rng.permutation(len(pts))
    check_degenerate(np.asarray(pts, float)[perm])


def test_rotated_lattice_and_triangular_lattice():
    i, j = np.meshgrid(np.arange(-6, 7), np.arange(-6, 7))
    rot = np.c_[(i + j).ravel(), (i - j).ravel()].astype(float)
    check_degenerate(rot)
    # a triangular lattice: every Delaunay triangle is equilateral up to rounding
    tri = np.c_[(i + 0.5 * (j % 2)).ravel(), (j * np.sqrt(3) / 2).ravel()]
    check_degenerate(tri)


# --------------------------------------------------------------------------------------
# 3. small cases worked out by hand
# --------------------------------------------------------------------------------------


def test_square_with_centre(checked):
    mesh = checked(aftmesh.cdt([(0, 0), (1, 0), (1, 1), (0, 1), (0.5, 0.5)]), domain_area=1.0)
    assert mesh.n_points == 5 and mesh.n_triangles == 4
    c = mesh.info["vertex_map"][4]
    # every triangle has the centre and one side of the square
    assert all(c in t for t in mesh.triangles.tolist())
    sides = {frozenset(t) - {c} for t in map(frozenset, mesh.triangles.tolist())}
    vm = mesh.info["vertex_map"]
    assert sides == {frozenset((vm[a], vm[b])) for a, b in ((0, 1), (1, 2), (2, 3), (3, 0))}
    assert mesh.info["merged_vertices"] == 0
    assert (mesh.regions == 0).all()


def test_square_with_square_hole(checked):
    V = [(0, 0), (2, 0), (2, 2), (0, 2), (0.5, 0.5), (1.5, 0.5), (1.5, 1.5), (0.5, 1.5)]
    S = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4)]
    mesh = checked(
        aftmesh.cdt(V, S, holes=[(1, 1)]),
        domain_area=3.0,
        input_segments=np.asarray(V, float)[np.asarray(S)],
    )
    assert mesh.n_triangles == 8
    assert mesh.area() == 3.0
    centroids = mesh.points[mesh.triangles].mean(axis=1)
    inside_hole = (np.abs(centroids - 1.0) < 0.5).all(axis=1)
    assert not inside_hole.any()
    assert sorted(mesh.segment_markers.tolist()) == list(range(8))
    # without the hole point the inner square is meshed too: 10 triangles, area 4
    mesh = checked(aftmesh.cdt(V, S), domain_area=4.0)
    assert mesh.n_triangles == 10


def test_segment_through_collinear_vertices_is_split(checked):
    V = [
        (0, 0),
        (2, 0),
        (2, 2),
        (0, 2),  # square ring
        (1, 0),  # on the bottom side
        (1, 1),
    ]  # on the diagonal 0-2
    S = [(0, 1), (1, 2), (2, 3), (3, 0), (0, 2)]
    mesh = checked(
        aftmesh.cdt(V, S), domain_area=4.0, input_segments=np.asarray(V, float)[np.asarray(S)]
    )
    vm = mesh.info["vertex_map"]
    got = {
        frozenset((int(u), int(v))): int(m)
        for (u, v), m in zip(mesh.segments.tolist(), mesh.segment_markers.tolist())
    }
    want = {(0, 4): 0, (4, 1): 0, (1, 2): 1, (2, 3): 2, (3, 0): 3, (0, 5): 4, (5, 2): 4}
    assert got == {frozenset((int(vm[a]), int(vm[b]))): m for (a, b), m in want.items()}
    # 5 boundary vertices, 1 interior: 5 - 2 + 2 = 5 triangles
    assert mesh.n_triangles == 5


def test_segment_through_several_collinear_vertices(checked):
    # a horizontal segment through 3 vertices, inside a triangle ring
    V = [(-1, -1), (5, -1), (2, 4), (0, 0), (4, 0), (1, 0), (3, 0), (2, 0)]
    S = [(0, 1), (1, 2), (2, 0), (3, 4)]
    mesh = checked(
        aftmesh.cdt(V, S), domain_area=15.0, input_segments=np.asarray(V, float)[np.asarray(S)]
    )
    vm = mesh.info["vertex_map"]
    pieces = {
        frozenset((int(u), int(v)))
        for (u, v), m in zip(mesh.segments.tolist(), mesh.segment_markers.tolist())
        if m == 3
    }
    chain = [3, 5, 7, 6, 4]
    assert pieces == {frozenset((int(vm[a]), int(vm[b]))) for a, b in zip(chain, chain[1:])}
    assert len(mesh.segments) == 3 + 4
    cross_check(V, S)


def test_duplicates_are_merged_and_reported(checked):
    V = [(0, 0), (1, 0), (1, 1), (0, 1), (0.5, 0.5), (0, 0), (0.5, 0.5), (0.5, 0.5)]
    mesh = checked(aftmesh.cdt(V), domain_area=1.0)
    assert mesh.info["merged_vertices"] == 3
    vm = mesh.info["vertex_map"]
    assert vm[5] == vm[0] and vm[6] == vm[4] and vm[7] == vm[4]
    assert len(set(vm.tolist())) == 5 and mesh.n_points == 5
    assert mesh.n_triangles == 4
    assert np.array_equal(mesh.points[vm], np.asarray(V, float))


def test_duplicates_referenced_by_segments(checked):
    # the ring uses the duplicate (index 4) of corner 1
    V = [(0, 0), (1, 0), (1, 1), (0, 1), (1, 0), (0.25, 0.75)]
    S = [(0, 4), (4, 2), (2, 3), (3, 0)]
    mesh = checked(aftmesh.cdt(V, S), domain_area=1.0)
    vm = mesh.info["vertex_map"]
    assert mesh.info["merged_vertices"] == 1 and vm[4] == vm[1]
    segs = {frozenset(map(int, s)) for s in mesh.segments.tolist()}
    assert segs == {frozenset((int(vm[a]), int(vm[b]))) for a, b in S}
    cross_check(V, S)


def test_regions_markers_land_on_the_right_triangles(checked):
    # three vertical strips of the rectangle [0,3]x[0,1]; the left gets 7, the right 9,
    # the middle no marker (0)
    V = [
        (0, 0),
        (1, 0),
        (2, 0),
        (3, 0),
        (3, 1),
        (2, 1),
        (1, 1),
        (0, 1),
        (0.5, 0.3),
        (1.5, 0.6),
        (2.5, 0.4),
    ]
    S = [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5), (5, 6), (6, 7), (7, 0), (1, 6), (2, 5)]
    mesh = checked(aftmesh.cdt(V, S, regions=[(0.2, 0.9, 7), (2.9, 0.1, 9)]), domain_area=3.0)
    cx = mesh.points[mesh.triangles].mean(axis=1)[:, 0]
    want = np.where(cx < 1, 7, np.where(cx > 2, 9, 0))
    assert np.array_equal(mesh.regions, want)
    # 3 strips, each with 4 corners and one interior point: 4 triangles each
    assert mesh.n_triangles == 12
    cross_check(V, S, None, [(0.2, 0.9, 7), (2.9, 0.1, 9)])


def test_region_markers_inside_and_around_an_inner_ring(checked):
    V = [(0, 0), (2, 0), (2, 2), (0, 2), (0.5, 0.5), (1.5, 0.5), (1.5, 1.5), (0.5, 1.5)]
    S = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4)]
    mesh = checked(aftmesh.cdt(V, S, regions=[(1, 1, 5), (0.1, 0.1, 3)]), domain_area=4.0)
    centroids = mesh.points[mesh.triangles].mean(axis=1)
    inner = (np.abs(centroids - 1.0) < 0.5).all(axis=1)
    assert (mesh.regions[inner] == 5).all() and (mesh.regions[~inner] == 3).all()
    assert inner.sum() == 2


@pytest.mark.parametrize(
    "regions,want",
    [
        ([(0.1, 0.1, 3), (1.9, 1.9, 4)], {4}),  # same region twice: the last wins
        # (as in Triangle)
        ([(1.2, 1.2, 5)], {0}),  # only inside the hole: ignored
        ([(0.1, 0.1, -2)], {-2}),  # negative markers are markers
    ],
)
def test_regions_and_holes_together_as_triangle_does(regions, want, checked):
    V = [(0, 0), (2, 0), (2, 2), (0, 2), (0.5, 0.5), (1.5, 0.5), (1.5, 1.5), (0.5, 1.5)]
    S = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4)]
    mesh = checked(aftmesh.cdt(V, S, holes=[(1, 1)], regions=regions), domain_area=3.0)
    assert set(mesh.regions.tolist()) == want
    cross_check(V, S, [(1, 1)], regions)


@pytest.mark.parametrize("seed", range(10))
def test_random_duplicates_are_merged(seed):
    """A random PSLG with copies of some of its vertices appended, and segments
    referring to the copies at random: the same CDT as without the copies."""
    rng = np.random.default_rng(500 + seed)
    case = pc.polygon_with_holes(
        rng, n_points=int(rng.integers(0, 100)), n_extra_segments=int(rng.integers(0, 10))
    )
    V, S = case["vertices"], case["segments"].copy()
    n = len(V)
    originals = rng.choice(n, size=max(1, n // 8), replace=False)
    V2 = np.vstack([V, V[originals]])
    copy_of = {int(o): n + k for k, o in enumerate(originals)}
    for k in range(len(S)):
        for e in range(2):
            if int(S[k, e]) in copy_of and rng.random() < 0.5:
                S[k, e] = copy_of[int(S[k, e])]
    mesh, _ = cross_check(V2, S, case["holes"], case["regions"], area=case["area"])
    assert mesh.info["merged_vertices"] == len(originals)
    vm = mesh.info["vertex_map"]
    assert all(vm[c] == vm[o] for o, c in copy_of.items())
    plain = aftmesh.cdt(V, case["segments"], holes=case["holes"], regions=case["regions"])
    assert plain.n_triangles == mesh.n_triangles


def test_region_marker_outside_int32_is_refused():
    with pytest.raises(InvalidInputError, match=r"regions\[0\]"):
        aftmesh.cdt(SQUARE, RING, regions=[(0.5, 0.5, 2**40)])


def test_no_segments_keeps_the_convex_hull(checked):
    # an L-shaped point set: the hull covers the notch
    V = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    mesh = checked(aftmesh.cdt(V), domain_area=3.5)
    assert mesh.n_triangles == 5  # 6 points, 5 on the hull: 2*6 - 2 - 5
    assert len(mesh.segments) == 0


def test_dangling_segment_outside_rings_is_removed(checked):
    # a closed triangle ring plus a segment hanging outside it, in the convex hull
    V = [(0, 0), (4, 0), (0, 4), (4, 4), (3, 3), (1.0, 1.0)]
    S = [(0, 1), (1, 2), (2, 0), (3, 4)]
    mesh = checked(aftmesh.cdt(V, S), domain_area=8.0)
    vm = mesh.info["vertex_map"]
    assert vm[3] == -1 and vm[4] == -1 and vm[5] >= 0
    assert len(mesh.segments) == 3
    cross_check(V, S)


# --------------------------------------------------------------------------------------
# 4. invalid input
# --------------------------------------------------------------------------------------

SQUARE = [(0, 0), (1, 0), (1, 1), (0, 1)]
RING = [(0, 1), (1, 2), (2, 3), (3, 0)]


@pytest.mark.parametrize(
    "bad,index", [((np.nan, 0.5), 2), ((0.5, np.inf), 4), ((-np.inf, 0), 0), ((1e300, 0), 1)]
)
def test_non_finite_or_huge_coordinates(bad, index):
    V = np.array(SQUARE + [(0.5, 0.5)], dtype=float)
    V[index] = bad
    with pytest.raises(InvalidInputError, match=rf"vertices\[{index}\]"):
        aftmesh.cdt(V)


@pytest.mark.parametrize(
    "V",
    [
        [(0, 0, 0), (1, 0, 0), (0, 1, 0)],
        [0, 1, 2, 3, 4, 5],
        [[(0, 0)], [(1, 0)], [(0, 1)]],
        [(0, 0), (1, 0), (0, 1, 2)],
        [("a", "b"), (1, 0), (0, 1)],
        "abc",
    ],
)
def test_malformed_vertices(V):
    with pytest.raises(InvalidInputError, match="vertices"):
        aftmesh.cdt(V)


@pytest.mark.parametrize(
    "S,pattern",
    [
        ([(0, 1, 2)], r"shape"),
        ([0, 1, 2, 3], r"shape"),
        ([(0, 4)], r"segments\[0\].*4"),
        ([(0, 1), (1, 2), (2, -1)], r"segments\[2\].*-1"),
        ([(0, 1), (2, 2)], r"segments\[1\]"),
        ([(0.5, 1), (1, 2)], r"integer"),
        ([(0, 1), (1, 2), (2, 10**12)], r"segments\[2\]"),
    ],
)
def test_malformed_segments(S, pattern):
    with pytest.raises(InvalidInputError, match=pattern):
        aftmesh.cdt(SQUARE, S)


def test_integer_valued_float_segments_are_accepted(checked):
    mesh = checked(aftmesh.cdt(SQUARE, np.asarray(RING, dtype=float)), domain_area=1.0)
    assert len(mesh.segments) == 4


def test_zero_length_segment_between_distinct_coincident_vertices():
    V = SQUARE + [(1, 0)]
    with pytest.raises(InvalidInputError, match=r"segments\[4\] = \[1, 4\]"):
        aftmesh.cdt(V, RING + [(1, 4)])


def test_crossing_segments_name_both():
    with pytest.raises(CrossingSegmentsError) as info:
        aftmesh.cdt(SQUARE, RING + [(0, 2), (1, 3)])
    assert set(info.value.segments) == {4, 5}
    assert "segments[4]" in str(info.value) and "segments[5]" in str(info.value)
    assert isinstance(info.value, ValueError)


def test_crossing_segment_after_a_split_names_input_indices():
    # segment 4 runs through vertex 4 (1, 1) before crossing segment 5 at (2, 2)
    V = [(0, 0), (4, 0), (4, 4), (0, 4), (1, 1), (3, 1), (1, 3)]
    S = RING + [(0, 2), (5, 6)]
    with pytest.raises(CrossingSegmentsError) as info:
        aftmesh.cdt(V, S)
    assert set(info.value.segments) == {4, 5}
    assert "segments[4]" in str(info.value) and "segments[5]" in str(info.value)


def test_crossing_in_a_larger_pslg_names_the_right_pair():
    rng = np.random.default_rng(11)
    case = pc.box_with_segments(rng, 200, 60)
    S = case["segments"].tolist()
    V = case["vertices"]
    # add a segment that crosses exactly one existing segment: a tiny cross
    a, b = V[S[10][0]], V[S[10][1]]
    mid = 0.5 * (a + b)
    d = np.array([-(b - a)[1], (b - a)[0]]) * 1e-4
    V2 = np.vstack([V, mid + d, mid - d])
    S2 = S + [(len(V), len(V) + 1)]
    with pytest.raises(CrossingSegmentsError) as info:
        aftmesh.cdt(V2, S2)
    assert set(info.value.segments) == {10, len(S)}
    assert f"segments[{len(S)}]" in str(info.value) and "segments[10]" in str(info.value)


def test_overlapping_collinear_segments_are_split_not_crossing(checked):
    # two segments along y = 1 that overlap on [2, 3]: each runs through an end of the
    # other, so both are split there and the pieces (1-2, 2-3, 3-3.5) are the segments
    V = [(0, 0), (4, 0), (4, 2), (0, 2), (1, 1), (3, 1), (2, 1), (3.5, 1)]
    S = RING + [(4, 5), (6, 7)]
    mesh = checked(
        aftmesh.cdt(V, S), domain_area=8.0, input_segments=np.asarray(V, float)[np.asarray(S)]
    )
    vm = mesh.info["vertex_map"]
    segs = {frozenset(map(int, s)) for s in mesh.segments.tolist()}
    want = {frozenset((int(vm[a]), int(vm[b]))) for a, b in RING + [(4, 6), (6, 5), (5, 7)]}
    assert segs == want
    # the shared piece 2-3 carries the first segment's marker, as in Triangle
    cross_check(V, S)


def test_t_junction_splits_the_touched_segment(checked):
    # segment 4 ends on the interior of segment 5 at an input vertex: no crossing
    V = [(0, 0), (4, 0), (4, 4), (0, 4), (2, 1), (2, 3), (1, 3), (3, 3)]
    S = RING + [(4, 5), (6, 7)]
    mesh = checked(
        aftmesh.cdt(V, S), domain_area=16.0, input_segments=np.asarray(V, float)[np.asarray(S)]
    )
    assert len(mesh.segments) == 4 + 1 + 2
    cross_check(V, S)


def test_cdt_is_deterministic_and_leaves_its_input_alone():
    rng = np.random.default_rng(77)
    case = pc.polygon_with_holes(rng, n_points=200, n_extra_segments=20)
    args = [case[k].copy() for k in ("vertices", "segments", "holes", "regions")]
    m1 = aftmesh.cdt(args[0], args[1], holes=args[2], regions=args[3])
    m2 = aftmesh.cdt(args[0], args[1], holes=args[2], regions=args[3])
    check_mesh(m1, domain_area=case["area"])
    for k, a in zip(("vertices", "segments", "holes", "regions"), args):
        assert np.array_equal(a, case[k])
    for name in ("points", "triangles", "neighbors", "segments", "segment_markers", "regions"):
        assert np.array_equal(getattr(m1, name), getattr(m2, name)), name
    assert np.array_equal(m1.info["vertex_map"], m2.info["vertex_map"])


def test_the_oracle_helpers_can_fail():
    """The comparison machinery itself: a flipped diagonal is caught exactly, and a
    different triangle set is caught by cross_check's set comparison."""
    V = np.array([(0, 0), (2, 0), (2.1, 1), (0, 1.2)])
    good = run_triangle(V, np.zeros((0, 2)), np.zeros((0, 2)), np.zeros((0, 3)))["triangles"]
    diag = [
        frozenset(e)
        for t in np.asarray(good).tolist()
        for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))
    ]
    inner = [e for e in set(diag) if diag.count(e) == 2][0]
    a, b = sorted(inner)
    c, d = sorted(set(range(4)) - {a, b})
    flipped = [(a, c, d), (b, c, d)]
    flipped = [
        t if exact_orient(exact_ints(V), [t[0]], [t[1]], [t[2]])[0] > 0 else t[::-1]
        for t in flipped
    ]
    assert exact_report(V, good, [])["non_delaunay"] == 0
    rep = exact_report(V, flipped, [])
    assert rep["non_delaunay"] == 1 and rep["not_ccw"] == 0
    # constraining the flipped diagonal makes it a valid CDT
    assert exact_report(V, flipped, [(c, d)])["non_delaunay"] == 0
    # the exact incircle agrees with the textbook sign convention
    Q = exact_ints([(0, 0), (1, 0), (0, 1), (0.9, 0.9), (1, 1), (2, 2)])
    assert exact_incircle(Q, [0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 4, 5]).tolist() == [1, 0, -1]


@pytest.mark.parametrize(
    "V",
    [
        [(0, 0), (1, 1), (2, 2)],
        [(0, 0), (1, 1), (2, 2), (3, 3), (-5, -5)],
        [(0, 1), (0, 2), (0, 3), (0, 1)],
        [(0.1 * i, 0.3) for i in range(20)],
    ],
)
def test_all_collinear_points(V):
    with pytest.raises(InvalidDomainError, match="collinear"):
        aftmesh.cdt(V)


@pytest.mark.parametrize("V", [[], [(0, 0)], [(0, 0), (1, 1)], np.zeros((0, 2))])
def test_fewer_than_three_points(V):
    with pytest.raises(InvalidDomainError, match="3"):
        aftmesh.cdt(V)


def test_three_points_two_of_them_equal():
    with pytest.raises(InvalidDomainError):
        aftmesh.cdt([(0, 0), (1, 1), (0, 0)])


@pytest.mark.parametrize(
    "holes,index",
    [([(5, 5)], 0), ([(0.5, 0.5), (-1, 0.5)], 1), ([(0.5, 0.5), (0.5, 0.5), (2, 2)], 2)],
)
def test_hole_point_outside_the_domain(holes, index):
    V = SQUARE + [(0.25, 0.25), (0.75, 0.25), (0.5, 0.75)]
    S = RING + [(4, 5), (5, 6), (6, 4)]
    with pytest.raises(InvalidDomainError, match=rf"holes\[{index}\]"):
        aftmesh.cdt(V, S, holes=holes)


def test_hole_point_in_the_hull_but_outside_every_ring():
    # a triangle ring inside the hull of the points: (3.5, 0.5) is in the hull, outside
    V = [(0, 0), (3, 0), (0, 3), (4, 0), (4, 4)]
    S = [(0, 1), (1, 2), (2, 0)]
    with pytest.raises(InvalidDomainError, match=r"holes\[0\]"):
        aftmesh.cdt(V, S, holes=[(3.5, 0.5)])


def test_region_point_outside_the_domain():
    with pytest.raises(InvalidDomainError, match=r"regions\[1\]"):
        aftmesh.cdt(SQUARE, RING, regions=[(0.5, 0.5, 1), (3, 3, 2)])


@pytest.mark.parametrize("holes", [[(np.nan, 0.5)], [(0.5, 0.5, 0.5)], [[0.5]]])
def test_malformed_holes(holes):
    with pytest.raises(InvalidInputError, match="holes"):
        aftmesh.cdt(SQUARE, RING, holes=holes)


@pytest.mark.parametrize("regions", [[(0.5, np.nan, 1)], [(0.5, 0.5)], [("x", 0.5, 1)]])
def test_malformed_regions(regions):
    with pytest.raises(InvalidInputError, match="regions"):
        aftmesh.cdt(SQUARE, RING, regions=regions)


# fuzzing: small integer PSLGs (full of duplicates, collinear points, crossings).  Their
# expected behaviour is decided exactly, with integer arithmetic, here.  Triangle is only
# asked about "clean" ones: it crashes or hangs on some of these degenerate inputs
# (duplicate vertices in segments, overlapping segments).


def _orient_exact(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def _fractions(V):
    from fractions import Fraction

    return [(Fraction(float(x)), Fraction(float(y))) for x, y in V]


def _on_closed_segment(a, b, p):
    return (
        _orient_exact(a, b, p) == 0
        and min(a[0], b[0]) <= p[0] <= max(a[0], b[0])
        and min(a[1], b[1]) <= p[1] <= max(a[1], b[1])
    )


def _proper_pairs(V, S):
    """Pairs whose four orientations are non-zero and opposite in pairs (rationals):
    what the kernel's grid test looks for, a crossing at an input vertex included."""
    X = _fractions(V)
    out = set()
    for i in range(len(S)):
        for j in range(i + 1, len(S)):
            a, b = X[S[i][0]], X[S[i][1]]
            c, d = X[S[j][0]], X[S[j][1]]
            if (
                _orient_exact(a, b, c) * _orient_exact(a, b, d) < 0
                and _orient_exact(c, d, a) * _orient_exact(c, d, b) < 0
            ):
                out.add((i, j))
    return out


def crossing_pairs(V, S):
    """Pairs of input segments whose interiors cross at a point that is not an input
    vertex (decided in rational arithmetic): the pairs that must raise
    CrossingSegmentsError."""
    X = _fractions(V)
    verts = set(X)
    out = set()
    for i, j in _proper_pairs(V, S):
        a, b = X[S[i][0]], X[S[i][1]]
        c, d = X[S[j][0]], X[S[j][1]]
        o3, o4 = _orient_exact(c, d, a), _orient_exact(c, d, b)
        t = o3 / (o3 - o4)
        if (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])) not in verts:
            out.add((i, j))
    return out


def all_collinear(V):
    pts = list(dict.fromkeys(_fractions(V)))
    return len(pts) < 3 or all(_orient_exact(pts[0], pts[1], p) == 0 for p in pts[2:])


def hull_ring(V):
    """Segments along the convex hull of the points (collinear hull points are found
    again by aftmesh's splitting; shapely may keep or drop them)."""
    hull = MultiPoint([tuple(map(float, v)) for v in V]).convex_hull
    coords = [tuple(map(float, c)) for c in np.asarray(hull.exterior.coords)[:-1]]
    index = {tuple(map(float, v)): i for i, v in reversed(list(enumerate(V)))}
    ring = [index[c] for c in coords]
    return [(ring[k], ring[(k + 1) % len(ring)]) for k in range(len(ring))], coords


def is_clean(V, S):
    """No duplicate points, segments or zero-length ones, and no vertex on a segment
    but its ends: inputs Triangle handles reliably."""
    X = _fractions(V)
    if len(set(X)) != len(X):
        return False
    if len({frozenset(s) for s in S}) != len(S) or any(a == b for a, b in S):
        return False
    return not any(
        _on_closed_segment(X[a], X[b], p) for a, b in S for k, p in enumerate(X) if k not in (a, b)
    )


# coordinate frames for the fuzzers: base + i * step for small integers i; the inexact
# steps make nearly collinear / nearly cocircular points and near-misses of vertices
FRAMES = [
    (0.0, 1.0),
    (0.0, 0.1),
    (0.0, 1 / 3),
    (0.5, 2.0**-45),
    (1e7, float(np.spacing(1e7))),
    (-3e-7, 1e-7),
]


@st.composite
def small_pslgs(draw):
    base, step = draw(st.sampled_from(FRAMES))
    n = draw(st.integers(0, 10))
    coord = st.integers(-3, 3)
    V = [
        (base + i * step, base + j * step)
        for i, j in draw(st.lists(st.tuples(coord, coord), min_size=n, max_size=n))
    ]
    idx = st.integers(-1, n) if draw(st.booleans()) else st.integers(0, max(n - 1, 0))
    S = draw(st.lists(st.tuples(idx, idx), max_size=8))
    # hole points at irrational-ish offsets, dropped if rounding puts them on a vertex
    # or a segment (where Triangle picks a side arbitrarily; see the regression test
    # for a hole point on a vertex)
    off = (np.sqrt(2) - 1, 1 / np.pi)
    H = [
        (base + (i + off[0]) * step, base + (j + off[1]) * step)
        for i, j in draw(st.lists(st.tuples(coord, coord), max_size=2))
    ]
    X = _fractions(V)
    H = [
        h
        for h in H
        if not any(
            _on_closed_segment(X[a], X[b], _fractions([h])[0])
            for a, b in S + [(k, k) for k in range(n)]
            if 0 <= a < n and 0 <= b < n
        )
    ]
    return V, S, H


@given(small_pslgs())
def test_fuzz_small_pslgs_never_crash(pslg):
    """Whatever the input: a valid exact CDT, or an InvalidInputError; and the right
    one, decided exactly."""
    V, S, H = pslg
    valid_idx = all(0 <= i < len(V) for s in S for i in s)
    try:
        mesh = aftmesh.cdt(V if V else np.zeros((0, 2)), S or None, holes=H or None)
    except CrossingSegmentsError as err:
        assert valid_idx and crossing_pairs(V, S), f"no crossing here: {err}"
        return
    except InvalidInputError as err:
        assert str(err)
        zero = valid_idx and any(V[a] == V[b] for a, b in S)
        assert not valid_idx or zero or all_collinear(V) or H, f"rejected: {err}"
        return
    assert len(V) >= 3 and valid_idx and not all_collinear(V)
    assert not any(V[a] == V[b] for a, b in S)
    assert not crossing_pairs(V, S)
    check_mesh(mesh)
    assert_exact_cdt(mesh)
    if not is_clean(V, S):
        return
    # against Triangle: same triangles (or count and area when not unique)
    cross_check(V, S, H, None)


@st.composite
def small_segment_graphs(draw):
    """Distinct points with 1..10 segments between distinct points: crossings,
    overlaps, segments through vertices (and, in inexact frames, near misses)."""
    base, step = draw(st.sampled_from(FRAMES))
    coord = st.integers(-3, 3)
    ij = draw(st.lists(st.tuples(coord, coord), min_size=3, max_size=10, unique=True))
    V = [(base + i * step, base + j * step) for i, j in ij]
    idx = st.integers(0, len(V) - 1)
    S = draw(st.lists(st.tuples(idx, idx).filter(lambda s: s[0] != s[1]), min_size=1, max_size=10))
    return V, S


def _grid_says(V, S):
    return _kernel.segments_cross(
        np.asarray(V, dtype=np.float64), np.asarray(S, dtype=np.int64).reshape(-1, 2)
    )


@given(small_segment_graphs())
def test_grid_crossing_test_is_exact(graph):
    """The grid test that spares a dict its CDT (crossings.pxi) answers 1 exactly when
    two segments cross (every crossing the CDT would refuse among them), else 0."""
    V, S = graph
    assert _grid_says(V, S) == (1 if _proper_pairs(V, S) else 0)
    if _grid_says(V, S) == 0:
        assert not crossing_pairs(V, S)


@pytest.mark.parametrize("seed", range(6))
def test_grid_crossing_test_finds_a_crossing_among_many_segments(seed):
    """Hundreds of short segments over a grid of many cells, with and without one
    crossing pair among them: the crossing is found wherever it is."""
    rng = np.random.default_rng(seed)
    n = 300
    start = rng.uniform(0, 10, (n, 2))
    ang = rng.uniform(0, np.pi, n)
    end = start + 0.05 * np.c_[np.cos(ang), np.sin(ang)]
    V = np.r_[start, end]
    S = np.c_[np.arange(n), np.arange(n) + n]
    expected = _proper_pairs(V.tolist(), S.tolist())
    assert _grid_says(V, S) == (1 if expected else 0)
    k = int(rng.integers(n))  # a segment across segment k's middle, at right angles
    mid, d = 0.5 * (V[k] + V[k + n]), V[k + n] - V[k]
    V2 = np.r_[V, [mid - 0.3 * d[::-1] * [1, -1], mid + 0.3 * d[::-1] * [1, -1]]]
    S2 = np.r_[S, [[2 * n, 2 * n + 1]]]
    assert _grid_says(V2, S2) == 1


def test_crossing_in_a_crowded_cell_is_still_refused():
    """A fan of segments from one vertex fills one grid cell, the grid test gives up
    (-1), and the CDT decides: the crossing added to the fan is refused as before."""
    ang = np.linspace(0, np.pi / 2, 400)
    V = np.r_[[[0.0, 0.0]], np.c_[np.cos(ang), np.sin(ang)], [[0.2, -0.1], [0.2, 0.5]]]
    S = np.r_[np.c_[np.zeros(400, dtype=int), np.arange(1, 401)], [[401, 402]]]
    assert _grid_says(V, S) == -1
    ring = [[401, 1], [1, 400], [400, 0], [0, 401]]  # any closed ring: a domain
    with pytest.raises(CrossingSegmentsError):
        aftmesh.generate({"vertices": V, "segments": np.r_[S, ring]}, 0.5)


@given(small_segment_graphs())
def test_fuzz_crossings_splits_and_overlaps(graph):
    """With the convex hull added as segments (so nothing is carved): a crossing is
    reported, naming a pair that really crosses, exactly when there is one; otherwise
    every input segment is covered by mesh segments (split at the vertices on it)."""
    V, S = graph
    if all_collinear(V):
        with pytest.raises(InvalidDomainError):
            aftmesh.cdt(V, S)
        return
    ring, hull_coords = hull_ring(V)
    allS = S + ring
    crossing = crossing_pairs(V, S)
    try:
        mesh = aftmesh.cdt(V, allS)
    except CrossingSegmentsError as err:
        assert crossing, f"no segments cross: {err}"
        i, j = sorted(err.segments)
        assert (i, j) in crossing, f"segments {i} and {j} do not cross: {err}"
        assert f"segments[{i}]" in str(err) and f"segments[{j}]" in str(err)
        return
    assert not crossing, f"crossing segments {sorted(crossing)} accepted"
    Vf = np.asarray(V, dtype=np.float64)
    # (the hull can be a sliver: its area is compared exactly, not by check_mesh)
    check_mesh(mesh, input_segments=Vf[np.asarray(allS)])
    assert_exact_cdt(mesh)
    assert exact_area(mesh.points, mesh.triangles) == exact_polygon_area(hull_coords)
    # every mesh segment is a piece of some input segment, and says which
    X = _fractions(V)
    P = _fractions(mesh.points)
    for (u, v), mk in zip(mesh.segments.tolist(), mesh.segment_markers.tolist()):
        assert 0 <= mk < len(allS)
        a, b = allS[mk]
        assert _on_closed_segment(X[a], X[b], P[u]) and _on_closed_segment(X[a], X[b], P[v])
    if is_clean(V, allS):
        cross_check(V, allS, None, None)


# --------------------------------------------------------------------------------------
# 5. near-degenerate inputs
# --------------------------------------------------------------------------------------


def _count_check(V, S=None, H=None):
    """check_mesh, the exact CDT property, and Triangle's count (set equality when
    Triangle's CDT is unique)."""
    return cross_check(V, S, H, None)


@pytest.mark.parametrize("exp", [45, 50, 52, 53])
def test_tiny_lattice_around_half(exp):
    h = 2.0**-exp
    i, j = np.meshgrid(np.arange(-4, 5), np.arange(-4, 5))
    V = 0.5 + h * np.c_[i.ravel(), j.ravel()]
    V = np.unique(V, axis=0)
    assert len(V) == 81 if exp <= 53 else True
    _count_check(V)


@pytest.mark.parametrize("seed", range(6))
def test_random_points_on_a_tiny_lattice(seed):
    rng = np.random.default_rng(seed)
    k = rng.integers(-300, 301, size=(300, 2))
    V = np.unique(0.5 + k * 2.0**-53, axis=0)
    _count_check(V)


@pytest.mark.parametrize("seed", range(6))
def test_tiny_lattice_with_segments(seed):
    rng = np.random.default_rng(40 + seed)
    h = 2.0**-45
    k = rng.integers(-200, 201, size=(200, 2)).astype(float)
    corners = np.array([(-250, -250), (250, -250), (250, 250), (-250, 250)], float)
    pts = np.vstack([corners, np.unique(k, axis=0)])
    S = pc.add_noncrossing_segments(
        rng, pts, 60, existing=RING, margin=1e-12, allowed=lambda i, j: i >= 4 and j >= 4
    )
    V = 0.5 + h * pts
    _count_check(V, S)


@pytest.mark.parametrize("seed", range(5))
def test_nearly_collinear_points(seed):
    rng = np.random.default_rng(100 + seed)
    # points on the line y = x / 3 (rounded: not exactly collinear) plus a few far ones
    x = np.sort(rng.random(200))
    line = np.c_[x, x / 3]
    # a second family: one ulp above or below an exact line y = 0.5 (exactly collinear)
    y = 0.5 + rng.integers(-2, 3, size=100) * 2.0**-53
    flat = np.c_[rng.random(100), y]
    far = np.array([(0.5, 10.0), (0.5, -10.0), (-3.0, 0.2)])
    V = np.unique(np.vstack([line, flat, far]), axis=0)
    _count_check(V)


def test_nearly_collinear_segment_chain():
    # a long chain of segments along a nearly straight line, inside a box ring
    n = 300
    x = np.linspace(0.01, 0.99, n)
    y = 0.5 + (np.arange(n) % 3 - 1) * 2.0**-52
    V = np.vstack([SQUARE, np.c_[x, y]]).astype(float)
    S = RING + [(4 + k, 5 + k) for k in range(n - 1)]
    _count_check(V, S)


@pytest.mark.parametrize("seed", range(5))
def test_large_coordinates_with_tiny_detail(seed):
    rng = np.random.default_rng(200 + seed)
    ulp = np.spacing(1e7)  # ~1.9e-9
    k = rng.integers(-500, 501, size=(400, 2))
    V = np.unique(1e7 + k * ulp, axis=0)
    _count_check(V)
    # and a polygon with holes moved to 1e7 and shrunk to 1e-6 size
    case = pc.polygon_with_holes(rng, n_points=100)
    W = 1e7 + case["vertices"] * 1e-6
    _count_check(W, case["segments"], 1e7 + case["holes"] * 1e-6)


@pytest.mark.parametrize("seed", range(8))
def test_scaled_by_1e_minus_6(seed):
    rng = np.random.default_rng(300 + seed)
    case = pc.polygon_with_holes(rng, n_extra_segments=10)
    for s in (1e-6, 1e-12, 1e6):
        cross_check(
            case["vertices"] * s,
            case["segments"],
            case["holes"] * s,
            np.c_[case["regions"][:, :2] * s, case["regions"][:, 2]],
        )


def test_kernel_predicates_match_rational_arithmetic():
    """check_mesh relies on _kernel's predicates: they must be exact."""
    rng = np.random.default_rng(9)
    cases = []
    # points nearly on a line through two random points
    for _ in range(300):
        a, b = rng.random(2), rng.random(2)
        t = rng.random()
        c = a + t * (b - a) + rng.integers(-2, 3, size=2) * 2.0**-54
        cases.append((a, b, c))
    # the triple from Triangle's spiral.q.1 sample that a floating-point orientation
    # gets wrong (exact value +5.2e-19)
    cases.append(
        (
            np.array([0.004999999999999942, 1.963]),
            np.array([-1.35, 0.436]),
            np.array([-0.6725000000000001, 1.1995]),
        )
    )
    P = np.asarray([p for c in cases for p in c])
    Q = exact_ints(P)
    idx = np.arange(len(P)).reshape(-1, 3)
    want = exact_orient(Q, idx[:, 0], idx[:, 1], idx[:, 2])
    got = np.array([_kernel.py_orient2d(*a, *b, *c) for a, b, c in cases])
    assert np.array_equal(np.sign(got), want), f"{int((np.sign(got) != want).sum())} wrong"
    got_many = _kernel.orient2d_many(np.ascontiguousarray(P), idx.astype(np.int32))
    assert np.array_equal(np.sign(got_many), want)
    # incircle: a point nearly on the circle through three others
    quads = []
    for _ in range(300):
        c0, r = rng.random(2), 0.1 + rng.random()
        ang = np.sort(rng.random(4)) * 2 * np.pi
        pts = c0 + r * np.c_[np.cos(ang), np.sin(ang)]
        quads.append(pts)
    # an exactly cocircular quadruple scaled by non-powers of two (rounded)
    quads.append(np.array([(3, 4), (-4, 3), (-3, -4), (5, 0)], float) * 0.1)
    P = np.vstack(quads)
    Q = exact_ints(P)
    idx = np.arange(len(P)).reshape(-1, 4)
    want = exact_incircle(Q, idx[:, 0], idx[:, 1], idx[:, 2], idx[:, 3])
    got = np.array([_kernel.py_incircle(*q[0], *q[1], *q[2], *q[3]) for q in quads])
    assert np.array_equal(np.sign(got), want), f"{int((np.sign(got) != want).sum())} wrong"
    got_many = _kernel.incircle_many(np.ascontiguousarray(P), idx.astype(np.int32))
    assert np.array_equal(np.sign(got_many), want)


# --------------------------------------------------------------------------------------
# regressions found while writing these tests
# --------------------------------------------------------------------------------------


def test_bare_points_give_the_hull_without_segments(checked):
    """Without input segments the domain is the convex hull and there are no segments
    (check_mesh then accepts hull edges that are not segments)."""
    mesh = checked(aftmesh.cdt([(0, 0), (1, 0), (1, 1), (0, 1), (0.5, 0.5)]), domain_area=1.0)
    assert len(mesh.segments) == 0 and len(mesh.segment_markers) == 0


def test_regression_point_strictly_inside_the_hull_by_5e_19():
    """From Triangle's spiral.q.1 sample: c is strictly left of a -> b (exact
    orientation +5.2e-19, below floating-point resolution), d far on the same side, so
    the hull is the triangle a, b, d with c inside: 3 triangles, not 2."""
    a = (0.004999999999999942, 1.963)
    b = (-1.35, 0.436)
    c = (-0.6725000000000001, 1.1995)
    d = (0.0, -1.0)
    V = np.array([a, b, c, d])
    Q = exact_ints(V)
    assert exact_orient(Q, [0], [1], [2])[0] == 1 and exact_orient(Q, [0], [1], [3])[0] == 1
    mesh = aftmesh.cdt(V)
    assert_exact_cdt(mesh)
    assert mesh.n_triangles == 3
    assert len(triangle.triangulate(dict(vertices=V), "pc")["triangles"]) == 3


def test_regression_segment_marker_of_a_segment_leaving_the_domain():
    """A segment with one end outside the domain (here 0-1: vertex 1 lies outside the
    triangle ring 0-2-4 and is carved away, vertex_map -1) must not relabel other
    segments.  cdt.segment_markers walked from its inside end towards points[-1] (the
    -1 of vertex_map used as an index: the last output point), and when that point is
    a segment neighbour, overwrote that segment's marker: for the input below the ring
    side 0-2 got marker 2 instead of 0.  Tried under every vertex numbering, since
    which point is last depends on it."""
    V0 = [(0, 1), (-1, 0), (1, -1), (0, 0), (-1, -1)]
    S0 = [(0, 2), (2, 4), (0, 1), (0, 4)]
    wrong = []
    for perm in itertools.permutations(range(len(V0))):
        new = {old: k for k, old in enumerate(perm)}
        V = [V0[o] for o in perm]
        S = [(new[a], new[b]) for a, b in S0]
        mesh = aftmesh.cdt(V, S)
        check_mesh(mesh)
        got = {
            frozenset(map(tuple, mesh.points[[u, v]].tolist())): int(k)
            for (u, v), k in zip(mesh.segments, mesh.segment_markers)
        }
        want = {
            frozenset((tuple(map(float, V[a])), tuple(map(float, V[b])))): k
            for k, (a, b) in enumerate(S)
            if k != 2
        }
        if got != want:
            wrong.append(perm)
    assert not wrong, f"{len(wrong)} of 120 numberings give wrong markers, e.g. {wrong[0]}"


def test_regression_hole_point_on_a_vertex_removes_nothing():
    """A hole point exactly at an input vertex passes the "inside the domain" check but
    carves nothing: the square hole below keeps its 4 triangles (12 in all, area 4).
    Triangle eats the hole (8 triangles, area 3); rejecting the hole point would be a
    fair policy too, silently ignoring it is not."""
    V = [(0, 0), (2, 0), (2, 2), (0, 2), (0.5, 0.5), (1.5, 0.5), (1.5, 1.5), (0.5, 1.5), (1, 1)]
    S = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4)]
    try:
        mesh = aftmesh.cdt(V, S, holes=[(1, 1)])
    except InvalidDomainError as err:
        assert "holes[0]" in str(err)
        return
    check_mesh(mesh)
    assert mesh.n_triangles == 8 and mesh.area() == 3.0
