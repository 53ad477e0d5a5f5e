"""The paper's claims about Basic_aft, checked on every mesh ``aftmesh.generate`` makes.

* §2.2: Basic_aft terminates with a valid triangulation of the domain whose input
  edges are unmodified (split_boundary=False) or exactly covered (the discretized
  boundary), whatever the order of Get_next_edge, and also with other subtasks that
  meet the minimal requirements (custom Strategy objects);
* New_is_preferred always false is a greedy algorithm: no point is added and the mesh
  has E_b + 2(m - 1) triangles (formula (3));
* Mesh_size_constraint: formula (4) (N_max never exceeded; below the greedy count is
  impossible) and formula (5) (no new vertex whose triangle would be smaller than A_min);
* Appendix, formula (6): T = E_b + 2 V_i + 2(m - 1) on every connected component,
  m + 1 being the number of boundary curves traced with the max-turning-angle rule;
* §3: with S taken from cd(S(E)) and the swaps of Add_triangle, the mesh is the
  constrained Delaunay triangulation of its vertices and the input edges (checked
  against Shewchuk's Triangle, exact arithmetic where points are cocircular);
* the compiled loop and the Python loop of Figure 5 give the same mesh; same input,
  same output.
"""

from __future__ import annotations

import math

import domain_cases as dc
import numpy as np
import pytest
import triangle
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from shapely import affinity
from shapely.geometry import LineString, Point, Polygon, box

import aftmesh
from aftmesh.aft import Strategy
from aftmesh.checks import check_mesh, count_formula
from aftmesh.mesh import triangle_quality

# check_mesh's own empty-circle test uses the kernel's incircle predicate (it was not
# exact at first: test_regression_check_mesh_incircle_not_exact).  The Delaunay
# property is also judged independently by dc.assert_cdt (Triangle, then exact
# rational arithmetic where points are cocircular).
CHECKER_DELAUNAY = True

SHAPELY_CASES = dc.shapely_cases()
SAMPLE_CASES = [dc.triangle_sample(n) for n in dc.TRIANGLE_SAMPLES]

# m of each connected component (sorted), known from how each domain was built: one
# closed boundary curve per hole, except that a hole touching the exterior ring or
# another hole at a vertex joins that curve (the paper's successor rule).
EXPECTED_M = {
    "square": [0],
    "ngon13": [0],
    "L": [0],
    "comb5": [0],
    "channel": [0],
    "serpentine": [0],
    "9holes-square": [9],
    "16holes-circle": [16],
    "hole-touch-vertex": [0],
    "hole-touch-edge": [0],
    "holes-touch": [1],
    "touch-corner": [0, 0],
    "touch-vertex-edge": [0, 0],
    "annulus": [1],
    "L+1e+06": [0],
    "annulus*1e-06": [1],
    "slot": [0],
    "spiral": [0],
    "sliver": [0],
    "poly:A": [1],
    "poly:double_hex": [2],
    "poly:double_hex2": [2],
    "poly:double_hex3": [2],
    "poly:face": [3],
    "poly:la": [0],
    "poly:square_circle_hole": [1],
}


# ------------------------------------------------------------------------ helpers
def segment_coords(mesh) -> np.ndarray:
    P = np.asarray(mesh.points)
    S = np.asarray(mesh.segments)
    return np.stack([P[S[:, 0]], P[S[:, 1]]], axis=1)


def assert_covers_boundary(mesh, edges) -> None:
    """split_boundary=True: the input edges are cut into pieces but not moved.  Every
    mesh segment lies on an input edge, the pieces add up to the input edges' total
    length, and every input vertex where the boundary turns is a mesh vertex."""
    E = np.asarray(edges, dtype=float)
    segs = segment_coords(mesh)
    scale = float(np.abs(E).max()) or 1.0
    for part in (segs[:, 0], segs[:, 1], 0.5 * (segs[:, 0] + segs[:, 1])):
        on = dc.points_on_edges(part, E, tol=1e-9)
        assert on.all(), f"mesh segment point {part[~on][0]} is on no input edge"
    total_in = np.linalg.norm(E[:, 1] - E[:, 0], axis=1).sum()
    total_out = np.linalg.norm(segs[:, 1] - segs[:, 0], axis=1).sum()
    assert abs(total_in - total_out) <= 1e-9 * total_in, (total_in, total_out)
    # input vertices where two input edges meet at an angle must stay vertices
    mesh_pts = dc.coordinate_keys(mesh.points)
    ends = {}
    for a, b in E:
        for p, q in ((a, b), (b, a)):
            ends.setdefault(tuple(p), []).append(q - p)
    for p, dirs in ends.items():
        straight = (
            len(dirs) == 2
            and abs(dirs[0][0] * dirs[1][1] - dirs[0][1] * dirs[1][0]) <= 1e-12 * scale * scale
            and np.dot(dirs[0], dirs[1]) < 0
        )
        if not straight:
            assert (float(p[0]), float(p[1])) in mesh_pts, f"corner {p} was lost"


def assert_count_formula(mesh, expected_m=None) -> list:
    """Formula (6) on every component; optionally the expected m of each."""
    rows = count_formula(mesh)
    # the number of components, counted independently of aftmesh.checks
    N = np.asarray(mesh.neighbors)
    t, k = np.nonzero(N >= 0)
    graph = coo_matrix((np.ones(len(t)), (t, N[t, k])), shape=(len(N), len(N)))
    assert len(rows) == connected_components(graph, directed=False)[0]
    for T, Eb, Vi, m in rows:
        assert T == Eb + 2 * Vi + 2 * (m - 1), dict(T=T, E_b=Eb, V_i=Vi, m=m)
    assert sum(r[0] for r in rows) == len(mesh.triangles)
    if expected_m is not None:
        assert sorted(r[3] for r in rows) == sorted(expected_m)
    return rows


def assert_valid(mesh, case=None, *, split_boundary=True, delaunay=True, area=None, edges=None):
    """Everything a mesh of `case` must satisfy, whatever the options."""
    if case is not None:
        area = case.area if area is None else area
        edges = case.edges if edges is None else edges
    check_mesh(
        mesh,
        domain_area=area,
        input_segments=edges if not split_boundary else None,
        delaunay=CHECKER_DELAUNAY and delaunay,
    )
    signs = dc.orient_signs(np.asarray(mesh.points), np.asarray(mesh.triangles))
    assert (signs > 0).all(), f"{int((signs <= 0).sum())} triangles not strictly CCW (exact)"
    if edges is not None:
        if split_boundary:
            assert_covers_boundary(mesh, edges)
        else:
            # the paper's assumption: the input edges are edges of the mesh, unmodified
            # (only cut where another input vertex lies on them)
            verts = (
                case.vertices
                if case is not None
                else np.unique(np.asarray(edges).reshape(-1, 2), axis=0)
            )
            assert dc.edge_keys(mesh.points, mesh.segments) == dc.split_at_vertices(edges, verts)
    if edges is not None:
        # no near-duplicate vertices: no mesh edge is much shorter than both the
        # shortest input edge and the size (the pieces of an input edge are at least
        # about a size long, and the algorithm refuses R too close to S)
        E = np.asarray(edges, dtype=float)
        shortest_in = np.linalg.norm(E[:, 1] - E[:, 0], axis=1).min()
        h = case.size if case is not None else shortest_in
        P = np.asarray(mesh.points)
        e = mesh.edges
        shortest_out = np.linalg.norm(P[e[:, 1]] - P[e[:, 0]], axis=1).min()
        assert shortest_out >= 1e-3 * min(shortest_in, h), (shortest_out, shortest_in, h)
    rows = assert_count_formula(mesh, EXPECTED_M.get(case.name) if case is not None else None)
    if case is not None and not isinstance(case.domain, dict):
        # no input vertex inside these domains: the interior vertices are exactly the
        # ones Basic_aft created (Update_internal), each strictly inside, the points
        # smoothing's valence splits added, and the interior ones of the minimum-angle
        # pass
        refined = mesh.info["min_angle"]["interior"] if mesh.info["min_angle"] else 0
        made = mesh.info["new_vertices"] + mesh.info["valence_splits"]
        assert sum(r[2] for r in rows) == made + refined
    if delaunay:
        dc.assert_cdt(mesh)
    return mesh


def same_mesh(a, b) -> bool:
    return (
        np.array_equal(a.points, b.points)
        and np.array_equal(a.triangles, b.triangles)
        and np.array_equal(a.segments, b.segments)
        and np.array_equal(a.regions, b.regions)
    )


def graded(x, y):
    """A size callable: fine near the origin, coarser away from it."""
    return 0.08 + 0.12 * np.hypot(x, y) / 3.0


# ------------------------------------------------------ termination and validity
@pytest.mark.parametrize("case", SHAPELY_CASES, ids=repr)
@pytest.mark.parametrize("scale", [1.0, 0.5])
def test_valid_mesh_constant_size(case, scale):
    mesh = aftmesh.generate(case.domain, case.size * scale)
    assert_valid(mesh, case)
    assert mesh.info["compiled_loop"] is True


@pytest.mark.parametrize("case", SHAPELY_CASES, ids=repr)
def test_valid_mesh_unsplit_boundary(case):
    mesh = aftmesh.generate(case.domain, case.size, split_boundary=False)
    assert_valid(mesh, case, split_boundary=False)
    # the input vertices are all there, unmoved
    assert dc.coordinate_keys(case.vertices) <= dc.coordinate_keys(mesh.points)


@pytest.mark.parametrize("case", SHAPELY_CASES, ids=repr)
def test_valid_mesh_callable_size(case):
    lo = case.vertices.min(axis=0)
    span = float((case.vertices.max(axis=0) - lo).max())

    def size(x, y):
        return case.size * (0.4 + 0.8 * np.hypot(x - lo[0], y - lo[1]) / span)

    mesh = aftmesh.generate(case.domain, size)
    assert_valid(mesh, case)


@pytest.mark.parametrize("case", SAMPLE_CASES, ids=repr)
@pytest.mark.parametrize("how", ["unsplit-size-none", "unsplit-size", "split-size"])
def test_triangle_sample_files(case, how):
    if how == "unsplit-size-none":
        mesh = aftmesh.generate(case.domain, None, split_boundary=False)
    elif how == "unsplit-size":
        mesh = aftmesh.generate(case.domain, case.size, split_boundary=False)
    else:
        mesh = aftmesh.generate(case.domain, case.size)
    assert_valid(mesh, case, split_boundary=how.startswith("split"))
    # every input vertex is a mesh vertex, isolated ones included
    assert dc.coordinate_keys(case.vertices) <= dc.coordinate_keys(mesh.points)


def test_box_sample_encloses_nothing():
    """box.poly: one dangling segment and a square ring that is all hole: no area."""
    with pytest.raises(aftmesh.InvalidDomainError):
        aftmesh.generate(triangle.get_data("box"), split_boundary=False)


@pytest.mark.parametrize("order", ["shortest", "longest", "oldest"])
@pytest.mark.parametrize(
    "case", [dc.comb(), dc.many_holes(3, "circle"), dc.annulus(), dc.triangle_sample("A")], ids=repr
)
def test_orders(case, order):
    mesh = aftmesh.generate(case.domain, case.size, order=order)
    assert_valid(mesh, case)


@pytest.mark.parametrize(
    "case",
    [
        dc.comb(),
        dc.many_holes(3, "square"),
        dc.serpentine(),
        dc.corner_touching_parts(),
        dc.triangle_sample("la"),
    ],
    ids=repr,
)
def test_without_swaps_still_valid(case):
    """Without the Delaunay swaps of Add_triangle the mesh need not be Delaunay, but it
    is a valid triangulation and formula (6) holds."""
    mesh = aftmesh.generate(case.domain, case.size, swaps=False)
    assert_valid(mesh, case, delaunay=False)


def test_boundary_discretization_does_not_depend_on_the_interior():
    """The boundary is discretized before Basic_aft and not modified by it: the
    greedy mesh and the full mesh with the same size have the same segments (unless
    smoothing slides the split points: slide_boundary)."""
    case = dc.annulus()
    for size in (0.2, graded):
        full = aftmesh.generate(case.domain, size, slide_boundary=False)
        greedy = aftmesh.generate(case.domain, size, greedy=True)
        assert_valid(greedy, case)
        assert dc.edge_keys(full.points, full.segments) == dc.edge_keys(
            greedy.points, greedy.segments
        )
        check_mesh(
            full,
            domain_area=case.area,
            input_segments=segment_coords(greedy),
            delaunay=CHECKER_DELAUNAY,
        )


# ---------------------------------------------------------------------- greedy
@pytest.mark.parametrize("case", SHAPELY_CASES, ids=repr)
def test_greedy_adds_no_point(case):
    mesh = aftmesh.generate(case.domain, case.size, greedy=True, split_boundary=False)
    assert_valid(mesh, case, split_boundary=False)
    assert dc.coordinate_keys(mesh.points) == dc.coordinate_keys(case.vertices)
    assert len(mesh.points) == len(case.vertices)
    assert mesh.info["new_vertices"] == 0
    # formula (3): a minimal triangulation, E_b + 2(m - 1) triangles per component
    for T, Eb, Vi, m in count_formula(mesh):
        assert Vi == 0
        assert T == Eb + 2 * (m - 1)


@pytest.mark.parametrize("case", SHAPELY_CASES[:8], ids=repr)
def test_greedy_with_split_boundary(case):
    """With the boundary discretized, greedy meshes only the boundary's vertices."""
    mesh = aftmesh.generate(case.domain, case.size, greedy=True)
    assert_valid(mesh, case)
    assert dc.points_on_edges(mesh.points, case.edges, tol=1e-9).all()
    for T, Eb, Vi, m in count_formula(mesh):
        assert Vi == 0 and T == Eb + 2 * (m - 1)


@pytest.mark.parametrize("case", SAMPLE_CASES, ids=repr)
def test_greedy_triangle_samples(case):
    """Greedy on a PSLG is its CDT: the same triangles as Triangle's, no point added
    (isolated input vertices and internal segments included)."""
    mesh = aftmesh.generate(case.domain, greedy=True, split_boundary=False)
    assert_valid(mesh, case, split_boundary=False)
    assert dc.coordinate_keys(mesh.points) == dc.coordinate_keys(case.vertices)
    d = case.domain
    ref = triangle.triangulate({k: d[k] for k in ("vertices", "segments", "holes") if k in d}, "p")
    assert len(mesh.triangles) == len(ref["triangles"])


# ------------------------------------------------------------------ N_max, A_min
@pytest.mark.parametrize(
    "case",
    [
        dc.square(),
        dc.l_shape(),
        dc.many_holes(3, "square"),
        dc.corner_touching_parts(),
        dc.hole_touching_boundary(),
        dc.triangle_sample("double_hex3"),
    ],
    ids=repr,
)
def test_max_triangles(case):
    greedy = aftmesh.generate(case.domain, case.size, greedy=True)
    full = aftmesh.generate(case.domain, case.size)
    g, f = len(greedy.triangles), len(full.triangles)
    assert f > g
    # formula (4) with N_max = the greedy count: no vertex can be added
    at_g = aftmesh.generate(case.domain, case.size, max_triangles=g)
    assert_valid(at_g, case)
    assert len(at_g.triangles) == g and len(at_g.points) == len(greedy.points)
    # (smoothing may still slide the split points along the boundary)
    fixed = aftmesh.generate(case.domain, case.size, max_triangles=g, slide_boundary=False)
    assert same_mesh(fixed, greedy)
    for n_max in sorted({g + 1, g + 2, g + 7, (g + f) // 2, f - 1}):
        mesh = aftmesh.generate(case.domain, case.size, max_triangles=n_max)
        assert_valid(mesh, case)
        assert len(mesh.triangles) <= n_max
        # formula (6) with the boundary fixed: each new vertex adds two triangles
        # (Basic_aft's, and smoothing's valence splits)
        made = mesh.info["new_vertices"] + mesh.info["valence_splits"]
        assert len(mesh.triangles) == g + 2 * made
        assert len(mesh.points) == len(greedy.points) + made
    with pytest.raises(aftmesh.InvalidSizeError):
        aftmesh.generate(case.domain, case.size, max_triangles=g - 1)


def test_max_triangles_below_greedy_count_unsplit():
    case = dc.many_holes(3, "square")
    # formula (3): E_b + 2(m - 1) = 40 + 16 triangles at least
    assert len(aftmesh.generate(case.domain, greedy=True, split_boundary=False).triangles) == 56
    mesh = aftmesh.generate(case.domain, split_boundary=False, max_triangles=56)
    assert len(mesh.triangles) == 56 and len(mesh.points) == 40
    for n in (55, 1):
        with pytest.raises(aftmesh.InvalidSizeError):
            aftmesh.generate(case.domain, split_boundary=False, max_triangles=n)


class SizeConstraintRecorder(Strategy):
    """The built-in subtasks, recording each Mesh_size_constraint question with the
    area A(E, R) computed here from the kernel's coordinates."""

    def __init__(self):
        self.asked = []

    def mesh_size_constraint(self, kernel, E, R):
        refuse = super().mesh_size_constraint(kernel, E, R)
        a, b = kernel.edge(E)
        (ax, ay), (bx, by) = kernel.vertex(a), kernel.vertex(b)
        area = 0.5 * ((bx - ax) * (R[1] - ay) - (by - ay) * (R[0] - ax))
        self.asked.append((float(R[0]), float(R[1]), area, bool(refuse)))
        return refuse


@pytest.mark.parametrize("case", [dc.square(), dc.l_shape(), dc.many_holes(3, "circle")], ids=repr)
@pytest.mark.parametrize("factor", [0.5, 1.0, 1.5])
def test_min_area_formula_5(case, factor):
    """Formula (5): a new vertex only when A(E, R) >= A_min.  With smoothing off every
    new vertex of the mesh is one of the R's that Mesh_size_constraint let through."""
    a_min = factor * (np.sqrt(3) / 4) * case.size**2
    rec = SizeConstraintRecorder()
    # (min_angle=None: the refinement pass adds vertices of its own after Basic_aft)
    mesh = aftmesh.generate(
        case.domain, case.size, min_area=a_min, smooth=0, strategy=rec, min_angle=None
    )
    assert_valid(mesh, case)
    assert rec.asked
    for x, y, area, refused in rec.asked:
        if area < a_min:
            assert refused, (x, y, area, a_min)
    allowed = {(x, y) for x, y, area, refused in rec.asked if not refused}
    assert all(area >= a_min for x, y, area, refused in rec.asked if not refused)
    boundary = aftmesh.generate(case.domain, case.size, greedy=True)
    new_pts = dc.coordinate_keys(mesh.points) - dc.coordinate_keys(boundary.points)
    assert len(new_pts) == mesh.info["new_vertices"]
    assert new_pts <= allowed
    # same mesh as the compiled loop
    assert same_mesh(
        mesh, aftmesh.generate(case.domain, case.size, min_area=a_min, smooth=0, min_angle=None)
    )


@pytest.mark.parametrize(
    "case", [dc.square(), dc.comb(), dc.many_holes(3, "circle"), dc.triangle_sample("A")], ids=repr
)
def test_min_area_fewer_vertices(case):
    """A_min refuses new vertices: a small A_min still lets the front add vertices,
    one above the area of an equilateral triangle of the size (every candidate
    triangle is about that, or smaller) refuses them all.  (Counts at different
    small A_min need not be monotone: the front evolves differently.)"""
    base = (np.sqrt(3) / 4) * case.size**2
    counts = []
    for factor in (0.0, 0.3, 3.0, 30.0):
        mesh = aftmesh.generate(case.domain, case.size, min_area=factor * base, min_angle=None)
        assert_valid(mesh, case)
        counts.append(mesh.info["new_vertices"])
    assert counts[0] > 0 and counts[1] > 0, counts
    assert counts[2] <= counts[1] and counts[3] <= counts[2], counts
    # no candidate triangle is ever that large: formula (5) refuses every vertex (the
    # split points not slid: greedy's never are)
    huge = aftmesh.generate(
        case.domain, case.size, min_area=1e6 * case.area, min_angle=None, slide_boundary=False
    )
    assert same_mesh(huge, aftmesh.generate(case.domain, case.size, greedy=True))


class NmaxRecorder(Strategy):
    def __init__(self):
        self.n_front = []

    def get_next_edge(self, kernel):
        self.n_front.append(len(kernel.front_edges()))
        return super().get_next_edge(kernel)


def test_max_triangles_python_loop():
    case = dc.l_shape()
    g = len(aftmesh.generate(case.domain, case.size, greedy=True).triangles)
    for n_max in (g, g + 9, g + 30):
        rec = NmaxRecorder()
        mesh = aftmesh.generate(case.domain, case.size, max_triangles=n_max, strategy=rec)
        assert_valid(mesh, case)
        assert mesh.info["compiled_loop"] is False
        assert len(mesh.triangles) <= n_max
        # one triangle per pass of the while loop; the last pass empties the front
        assert len(rec.n_front) == len(mesh.triangles) + 1 and rec.n_front[-1] == 0
        assert same_mesh(mesh, aftmesh.generate(case.domain, case.size, max_triangles=n_max))


class _Drained(Exception):
    pass


class DrainQueue(Strategy):
    """Pops the whole initial queue at the first call, recording (length, half-edge)."""

    def get_next_edge(self, kernel):
        self.popped = []
        while (e := kernel.get_next_edge()) >= 0:
            a, b = (np.asarray(kernel.vertex(v)) for v in kernel.edge(e))
            self.popped.append((float(np.sum((b - a) ** 2)), e))
        raise _Drained


@pytest.mark.parametrize("order", ["shortest", "longest", "oldest"])
def test_get_next_edge_order_is_length_class_then_age(order):
    """The queue gives the front edges by length class (eighths of an octave of the
    length: floor(4 log2 |E|^2)), shortest or longest first, the oldest first within a
    class (the initial front is queued in half-edge order); "oldest" is plain age."""
    rng = np.random.default_rng(5)
    angles = np.sort(rng.uniform(0, 2 * np.pi, 40))
    radii = rng.uniform(0.3, 1.0, 40)
    star = Polygon(np.column_stack([radii * np.cos(angles), radii * np.sin(angles)]))
    drain = DrainQueue()
    with pytest.raises(_Drained):
        aftmesh.generate(star, 10.0, order=order, strategy=drain)
    lengths, edges = map(np.array, zip(*drain.popped))
    assert len(edges) == len(set(edges)) >= 40
    classes = np.floor(4 * np.log2(lengths))
    if order == "oldest":
        assert np.all(np.diff(edges) > 0)
        return
    if order == "longest":
        classes = -classes
    assert np.all(np.diff(classes) >= 0)
    for c in np.unique(classes):
        assert np.all(np.diff(edges[classes == c]) > 0)


@pytest.mark.parametrize("k", [-7, -4, -2, 0, 3])
def test_length_classes_are_log2s_at_the_class_boundaries(k):
    """The queue's length class is floor(4 log2 |E|^2) as the C library's log2 rounds
    it, also within a rounding error of a class boundary, where the rounding and not
    the exact value decides (the kernel reads the class from the bits of |E|^2
    elsewhere).  Rectangles whose sides are a power of two, or 2**(1/8) times one, and
    the doubles beside it: the first popped edges come in (class, age) order."""
    for base in (2.0**k, 2.0 ** (k + 0.125)):
        for w in (np.nextafter(base, 0), base, np.nextafter(base, np.inf)):
            for h in (np.nextafter(base, 0), base):
                drain = DrainQueue()
                rect = Polygon([(0, 0), (w, 0), (w, h), (0, h)])
                with pytest.raises(_Drained):
                    aftmesh.generate(rect, 100.0 * base, strategy=drain)
                keys = [(math.floor(4 * math.log2(q)), e) for q, e in drain.popped[:4]]
                assert keys == sorted(keys)


def test_seams_where_two_lattices_meet_stay_narrow(checked):
    """On a uniform size the fronts of the square's four sides grow lattices that meet
    along the diagonals.  Where two meet out of step, the proximity rules reach farther
    (LATTICE_PROXIMITY) and take the seam's vertices: with the plain reach, the seam
    from one corner widened into a wedge of disorder over a quarter of this square, and
    2.0 % of the front's triangles had a radius ratio below 0.9 (0.19 % now)."""
    h = 0.0018
    n = round(1 / h)
    t = np.arange(n) / n
    ring = np.concatenate(
        [np.c_[t, 0 * t], np.c_[1 + 0 * t, t], np.c_[1 - t, 1 + 0 * t], np.c_[0 * t, 1 - t]]
    )
    square = {
        "vertices": ring,
        "segments": np.c_[np.arange(4 * n), (np.arange(4 * n) + 1) % (4 * n)],
    }
    mesh = checked(aftmesh.generate(square, h, split_boundary=False, smooth=0, min_angle=None))
    rr = triangle_quality(mesh.points, mesh.triangles)["radius_ratio"]
    assert (rr < 0.9).mean() < 0.005


# ------------------------------------------------------ compiled loop vs Python loop
class _FrontOrder(Strategy):
    """The built-in subtasks, recording each edge Get_next_edge hands out."""

    def __init__(self):
        self.edges = []

    def get_next_edge(self, kernel):
        E = super().get_next_edge(kernel)
        if E >= 0:
            a, b = kernel.edge(E)
            self.edges.append((kernel.vertex(a), kernel.vertex(b)))
        return E


def test_the_first_row_along_the_boundary_comes_first():
    """Get_next_edge (shortest first) hands out the edges on the input segments,
    shortest first, before any edge a step made: the rows from a small hole's short
    edges used to run ahead of the long outer edges' own first row."""
    domain = box(0, 0, 2, 1).difference(Point(0.15, 0.5).buffer(0.02, 8))
    rec = _FrontOrder()
    aftmesh.generate(domain, 0.1, strategy=rec, smooth=0, min_angle=None)
    outline = domain.boundary
    on_boundary = [
        outline.distance(Point(0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]))) < 1e-12
        for a, b in rec.edges
    ]
    first = on_boundary.index(False)
    assert first > 20 and not any(on_boundary[first:])
    lengths = [math.dist(a, b) for a, b in rec.edges[:first]]
    # length classes are eighths of an octave: a later edge is never a class shorter
    assert all(m >= l * 2 ** (-1 / 8) * (1 - 1e-9) for l, m in zip(lengths, lengths[1:]))
    assert lengths[0] < 0.02 < 0.09 < lengths[-1]


class SameGetNextEdge(Strategy):
    def get_next_edge(self, kernel):
        return kernel.get_next_edge()


@pytest.mark.parametrize(
    "case",
    [
        dc.square(),
        dc.l_shape(),
        dc.comb(3),
        dc.many_holes(3, "circle"),
        dc.hole_touching_boundary(),
        dc.corner_touching_parts(),
        dc.triangle_sample("face"),
        # a disc at its edges' length: rows snap to the lattice (lattice.pxi)
        dc.shapely_case("disc", Point(0, 0).buffer(1.0, 16), 2.0 * np.sin(np.pi / 64)),
        # a hole's short edges make the size a field with a plateau, whose inner rows
        # snap to the lattice of the number (lattice.pxi)
        dc.shapely_case(
            "plateau", box(0, 0, 2, 1).difference(Point(0.5, 0.5).buffer(0.05, 4)), 0.06
        ),
    ],
    ids=repr,
)
@pytest.mark.parametrize(
    "options",
    [{}, {"order": "longest"}, {"order": "oldest"}, {"swaps": False}, {"size": graded}],
    ids=["default", "longest", "oldest", "noswaps", "graded"],
)
def test_python_loop_same_as_compiled(case, options):
    options = dict(options)
    size = options.pop("size", case.size)
    # the scaffold is the compiled loop's alone (the Python loop is Figure 5 as it
    # stands), so the loop it must equal is the compiled one without it
    compiled = aftmesh.generate(case.domain, size, scaffold=False, **options)
    python = aftmesh.generate(case.domain, size, strategy=SameGetNextEdge(), **options)
    assert compiled.info["compiled_loop"] is True
    assert python.info["compiled_loop"] is False
    assert_valid(python, case, delaunay=options.get("swaps", True))
    assert np.array_equal(compiled.points, python.points)
    assert np.array_equal(compiled.triangles, python.triangles)
    assert np.array_equal(compiled.neighbors, python.neighbors)
    assert np.array_equal(compiled.segments, python.segments)
    assert compiled.info["new_vertices"] == python.info["new_vertices"]


def test_builtin_strategy_instance_runs_compiled():
    case = dc.l_shape()
    mesh = aftmesh.generate(case.domain, case.size, strategy=Strategy())
    assert mesh.info["compiled_loop"] is True
    assert same_mesh(mesh, aftmesh.generate(case.domain, case.size))


class NeverNew(Strategy):
    def new_is_preferred(self, kernel, E, R, S, h):
        return False


class FlatCandidate(Strategy):
    """R at 40 % of the built-in height above E: flatter triangles."""

    def compute_new_candidate(self, kernel, E):
        x, y, h = super().compute_new_candidate(kernel, E)
        a, b = kernel.edge(E)
        (ax, ay), (bx, by) = kernel.vertex(a), kernel.vertex(b)
        mx, my = 0.5 * (ax + bx), 0.5 * (ay + by)
        return mx + 0.4 * (x - mx), my + 0.4 * (y - my), h


class FarCandidate(Strategy):
    """R five sizes away on the left: usually not visible, sometimes outside."""

    def compute_new_candidate(self, kernel, E):
        a, b = kernel.edge(E)
        (ax, ay), (bx, by) = kernel.vertex(a), kernel.vertex(b)
        x, y, h = super().compute_new_candidate(kernel, E)
        L = np.hypot(bx - ax, by - ay)
        return 0.5 * (ax + bx) - 5 * h * (by - ay) / L, 0.5 * (ay + by) + 5 * h * (bx - ax) / L, h


class AlwaysNew(Strategy):
    """New_is_preferred true unless R and S coincide (the minimal requirement)."""

    def new_is_preferred(self, kernel, E, R, S, h):
        return tuple(kernel.vertex(S)) != (R[0], R[1])


class HighestEdgeFirst(Strategy):
    """Get_next_edge by its own rule: the front edge with the highest midpoint."""

    def get_next_edge(self, kernel):
        best, key = -1, None
        for e in kernel.front_edges().tolist():
            a, b = kernel.edge(e)
            (ax, ay), (bx, by) = kernel.vertex(a), kernel.vertex(b)
            k = (ay + by, ax + bx, e)
            if key is None or k > key:
                best, key = e, k
        return best


@pytest.mark.parametrize(
    "case",
    [
        dc.square(),
        dc.l_shape(),
        dc.many_holes(3, "circle"),
        dc.triangle_sample("face"),
        dc.triangle_sample("A"),
    ],
    ids=repr,
)
def test_strategy_never_new_is_greedy(case):
    for split in (False, True):
        mesh = aftmesh.generate(
            case.domain,
            case.size,
            strategy=NeverNew(),
            split_boundary=split,
            min_angle=None,
            slide_boundary=False,  # greedy's split points never slide
        )
        assert mesh.info["compiled_loop"] is False
        assert_valid(mesh, case, split_boundary=split)
        greedy = aftmesh.generate(case.domain, case.size, greedy=True, split_boundary=split)
        assert same_mesh(mesh, greedy)
        assert mesh.info["new_vertices"] == 0


@pytest.mark.parametrize(
    "strategy", [FlatCandidate, FarCandidate, HighestEdgeFirst], ids=lambda s: s.__name__
)
@pytest.mark.parametrize(
    "case",
    [dc.square(), dc.l_shape(), dc.hole_touching_boundary(), dc.holes_touching_each_other()],
    ids=repr,
)
def test_custom_strategies_give_valid_meshes(case, strategy):
    mesh = aftmesh.generate(case.domain, case.size, strategy=strategy())
    assert mesh.info["compiled_loop"] is False
    assert_valid(mesh, case)


@pytest.mark.parametrize("case", [dc.square(), dc.l_shape(), dc.many_holes(3, "square")], ids=repr)
def test_always_new_with_max_triangles(case):
    """Any New_is_preferred is allowed; formula (4) still bounds the mesh."""
    g = len(aftmesh.generate(case.domain, case.size, greedy=True).triangles)
    n_max = g + 40
    mesh = aftmesh.generate(case.domain, case.size, max_triangles=n_max, strategy=AlwaysNew())
    assert_valid(mesh, case)
    assert len(mesh.triangles) <= n_max


def test_strategy_that_stops_early_is_an_error():
    class Quitter(Strategy):
        def get_next_edge(self, kernel):
            return -1

    with pytest.raises(aftmesh.InvalidOptionError):
        aftmesh.generate(dc.square().domain, 0.2, strategy=Quitter())


@pytest.mark.parametrize(
    "option",
    [
        {"greedy": 0},  # equals False, but a flag must be a bool
        {"smooth": 4.0},  # equals the default 4, but rounds are an integer
        {"order": "Shortest"},
        {"min_angle": 40.0},
    ],
    ids=repr,
)
def test_options_equal_to_a_default_are_still_checked(option):
    """generate skips check_options only for the default objects themselves, so a
    value that compares equal to a default (0 == False, 4.0 == 4) is still refused,
    as is any other bad value given."""
    with pytest.raises(aftmesh.InvalidOptionError):
        aftmesh.generate(dc.square().domain, 0.5, **option)


# ------------------------------------------------------------------ determinism
@pytest.mark.parametrize(
    "case",
    [dc.comb(), dc.many_holes(4, "circle"), dc.vertex_on_edge_parts(), dc.triangle_sample("la")],
    ids=repr,
)
def test_deterministic(case):
    runs = [aftmesh.generate(case.domain, case.size) for _ in range(2)]
    runs.append(aftmesh.generate(case.domain, graded))
    runs.append(aftmesh.generate(case.domain, graded))
    for a, b in (runs[:2], runs[2:]):
        assert_valid(a, case)
        for name in ("points", "triangles", "neighbors", "segments", "regions", "segment_markers"):
            assert getattr(a, name).tobytes() == getattr(b, name).tobytes(), name


def test_deterministic_across_processes():
    """Same input in fresh interpreters with different hash seeds: same bytes."""
    import hashlib
    import os
    import subprocess
    import sys

    code = (
        "import hashlib, numpy as np, aftmesh, sys; sys.path.insert(0, 'tests');"
        "import domain_cases as dc; c = dc.many_holes(3, 'circle');"
        "m = aftmesh.generate(c.domain, c.size);"
        "h = hashlib.sha256(); [h.update(np.ascontiguousarray(a).tobytes()) for a in "
        "(m.points, m.triangles, m.segments)]; print(h.hexdigest())"
    )
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    # the child imports the same aftmesh as this process (installed or from src/)
    package_root = os.path.dirname(os.path.dirname(os.path.abspath(aftmesh.__file__)))
    digests = set()
    for seed in ("0", "12345"):
        env = dict(
            os.environ,
            PYTHONHASHSEED=seed,
            PYTHONPATH=os.pathsep.join([package_root, os.environ.get("PYTHONPATH", "")]),
        )
        out = subprocess.run(
            [sys.executable, "-c", code],
            cwd=here,
            env=env,
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert out.returncode == 0, out.stderr
        digests.add(out.stdout.strip())
    c = dc.many_holes(3, "circle")
    m = aftmesh.generate(c.domain, c.size)
    h = hashlib.sha256()
    for a in (m.points, m.triangles, m.segments):
        h.update(np.ascontiguousarray(a).tobytes())
    digests.add(h.hexdigest())
    assert len(digests) == 1


# ------------------------------------------------------------------- hypothesis
SIZES = st.sampled_from([0.15, 0.3, "graded"])


def _size(s):
    return graded if s == "graded" else s


@given(poly=dc.star_polygons(), size=SIZES)
def test_random_star_polygons(poly, size):
    case = dc.shapely_case("star", poly, 0.3)
    mesh = aftmesh.generate(poly, _size(size))
    assert_valid(mesh, case)
    assert_count_formula(mesh, expected_m=[0])


@given(poly=dc.star_polygons(), size=SIZES)
def test_random_star_polygons_unsplit(poly, size):
    case = dc.shapely_case("star", poly, 0.3)
    mesh = aftmesh.generate(poly, _size(size), split_boundary=False)
    assert_valid(mesh, case, split_boundary=False)


@given(poly=dc.star_polygons())
def test_random_star_polygons_greedy(poly):
    case = dc.shapely_case("star", poly, 0.3)
    mesh = aftmesh.generate(poly, greedy=True, split_boundary=False)
    assert_valid(mesh, case, split_boundary=False)
    n = len(poly.exterior.coords) - 1
    assert len(mesh.points) == n and len(mesh.triangles) == n - 2


@given(poly=dc.polygons_with_circular_holes(), size=SIZES)
def test_random_circular_holes(poly, size):
    case = dc.shapely_case("holes", poly, 0.3)
    mesh = aftmesh.generate(poly, _size(size))
    assert_valid(mesh, case)
    assert_count_formula(mesh, expected_m=[len(poly.interiors)])


@pytest.mark.parametrize("turn", [29.0, 47.0])
def test_lattice_rows_follow_the_longest_straight_side(checked, turn):
    """A slot with round ends: the rows from its straight sides meet the lattice that
    the rows from its ends give way to.  With the lattice's rows along x, the turned
    slot's seams made a mean radius ratio of 0.9948-0.9952; along the longest straight
    side (lattice.pxi, LATTICE_ALIGN_RUN), 0.9958-0.9959 at every turn."""
    slot = affinity.rotate(LineString([(0, 0), (2, 0)]).buffer(0.5, 32), turn, origin=(0.1, 0.2))
    mesh = checked(aftmesh.generate(slot, 0.03), domain_area=slot.area)
    assert mesh.quality()["radius_ratio_mean"] > 0.9955


@pytest.mark.parametrize("turn", [0.0, 17.0, 45.0])
def test_rows_well_inside_a_plateau_give_way_to_one_lattice(checked, turn):
    """A number size over a rectangle with two small polygonal holes: the holes' short
    edges make the size a field graded up to the number, which then holds over the
    inside (a plateau).  The fronts of the sides and of the holes met there in seams of
    vertices of five and seven (mean radius ratio 0.9910-0.9914); with the rows four
    or more from the boundary moving onto one lattice of the number (lattice.pxi),
    0.9949-0.9950 at every turn."""
    domain = box(0, 0, 2, 1).difference(Point(0.5, 0.5).buffer(0.05, 4))
    domain = affinity.rotate(domain.difference(Point(1.4, 0.4).buffer(0.03, 3)), turn)
    mesh = checked(aftmesh.generate(domain, 0.03), domain_area=domain.area)
    assert mesh.quality()["radius_ratio_mean"] > 0.994


@pytest.mark.parametrize(
    ("gap", "radius", "h"),
    [(0.12, 0.03, 0.03), (0.15, 0.02, 0.03), (0.1, 0.04, 0.025), (0.2, 0.03, 0.04),
     (0.12, 0.015, 0.03)],
)  # fmt: skip
def test_rows_from_a_small_hole_meet_the_first_row_of_a_straight_side(checked, gap, radius, h):
    """A small hole near a straight side: the rings growing from its short edges
    reached the side before the side's own first row, and met its fixed vertices in
    flat triangles (mean radius ratio of the triangles on the side 0.964-0.975, some
    at 0.73-0.80).  With the boundary's first row first they meet free vertices,
    which smoothing settles: 0.979-0.990."""
    domain = box(0, 0, 2, 1).difference(Point(gap, 0.5).buffer(radius, 8))
    mesh = checked(aftmesh.generate(domain, h), domain_area=domain.area)
    on_side = (np.abs(mesh.points[mesh.triangles][:, :, 0]) < 1e-12).any(axis=1)
    rr = triangle_quality(mesh.points, mesh.triangles)["radius_ratio"][on_side]
    assert rr.mean() > 0.977


def _staircase(steps: int, step: float) -> Polygon:
    # a right triangle's hypotenuse made a staircase: 90 and 270 degree input corners
    pts = [(0.0, 0.0), (steps * step, 0.0)]
    x, y = steps * step, 0.0
    for _ in range(steps):
        y += step
        pts.append((x, y))
        x -= step
        pts.append((x, y))
    return Polygon(pts)


@pytest.mark.parametrize(("steps", "step", "h"), [(20, 0.5, 1.0), (12, 1.0, 1.3)])
def test_wide_input_corners_are_shared_by_two_triangles(checked, steps, step, h):
    """A staircase (a pixelated outline, as rw-earcut-rain's): where the unmeshed
    triangle on an input edge filled a 90 degree corner alone, the corner got one
    right triangle (radius ratio 0.83), 54 and 29 triangles of radius ratio <= 0.9
    here; with R on the corner's bisector (front.pxi's _split_wide_corner) two halves
    share it: 24 and 25, mean radius ratio 0.938 -> 0.954 and 0.939 -> 0.951."""
    domain = _staircase(steps, step)
    mesh = checked(aftmesh.generate(domain, h), domain_area=domain.area)
    rr = triangle_quality(mesh.points, mesh.triangles)["radius_ratio"]
    assert (rr <= 0.9).sum() <= 27
    assert rr.mean() > 0.948


@settings(max_examples=25)
@given(domain=dc.curved_domains())
def test_random_curved_domains_snapping_to_the_lattice_stay_valid(domain):
    """Under one constant size, rows from a curved boundary move R onto one lattice
    (lattice.pxi).  R stays a candidate like any other, so the mesh is a valid CDT
    holding the minimum-angle bound, on discs, ellipses, slots, rounded boxes and
    holed discs at any turn and place."""
    poly, size = domain
    case = dc.shapely_case("curved", poly, size)
    mesh = aftmesh.generate(poly, size)
    assert_valid(mesh, case)
    assert_count_formula(mesh, expected_m=[len(poly.interiors)])
    assert mesh.info["min_angle"]["reached"], mesh.info["min_angle"]


@given(poly=dc.polygons_with_circular_holes())
def test_random_circular_holes_greedy(poly):
    case = dc.shapely_case("holes", poly, 0.3)
    mesh = aftmesh.generate(poly, greedy=True, split_boundary=False)
    assert_valid(mesh, case, split_boundary=False)
    m = len(poly.interiors)
    assert len(mesh.points) == len(case.vertices)
    assert len(mesh.triangles) == len(case.edges) + 2 * (m - 1)


@settings(max_examples=12)
@given(
    poly=dc.star_polygons(max_vertices=10),
    size=st.sampled_from([0.2, "graded"]),
    order=st.sampled_from(["shortest", "longest", "oldest"]),
)
def test_random_python_loop_same_as_compiled(poly, size, order):
    compiled = aftmesh.generate(poly, _size(size), order=order, scaffold=False)
    python = aftmesh.generate(poly, _size(size), order=order, strategy=SameGetNextEdge())
    assert_valid(python, dc.shapely_case("star", poly, 0.3))
    assert same_mesh(compiled, python)


@settings(max_examples=25)
@given(
    poly=dc.polygons_with_circular_holes(max_holes=3),
    order=st.sampled_from(["shortest", "longest", "oldest"]),
    slack=st.integers(0, 60),
)
def test_random_circular_holes_options(poly, order, slack):
    case = dc.shapely_case("holes", poly, 0.3)
    g = len(aftmesh.generate(poly, 0.3, greedy=True).triangles)
    mesh = aftmesh.generate(poly, 0.3, order=order, max_triangles=g + slack)
    assert_valid(mesh, case)
    assert len(mesh.triangles) <= g + slack


# ----------------------------------------------------------------- regressions
def _cocircular_mirror_quad():
    """(a, 1), (1, a), (1, b), (b, 1): mirror images across y = x, hence an isosceles
    trapezoid, hence exactly cocircular in floating point as in the reals."""
    return np.array([[0.7222, 1.0], [1.0, 0.7222], [1.0, 0.7778], [0.7778, 1.0]])


def test_regression_check_mesh_incircle_not_exact():
    """check_mesh reports an exactly cocircular pair of triangles as non-Delaunay:
    its incircle predicate (the kernel's) rounds instead of being exact."""
    P = _cocircular_mirror_quad()
    assert dc.incircle_signs(P, np.array([[0, 1, 2, 3]]))[0] == 0  # exact: cocircular
    mesh = aftmesh.Mesh(
        points=P,
        triangles=[[0, 1, 2], [0, 2, 3]],
        neighbors=[[-1, 1, -1], [-1, -1, 0]],
        segments=[[0, 1], [1, 2], [2, 3], [3, 0]],
        regions=[0, 0],
    )
    check_mesh(mesh, domain_area=Polygon(P).area, delaunay=True)


def test_regression_greedy_not_cdt_double_hex():
    """Greedy on Triangle's double_hex.poly must be its CDT (no point is added, S comes
    from cd(S(E))), but two triangles have the apex of their neighbour strictly inside
    their circumcircle in exact arithmetic: near-cocircular points on the rings, decided
    by the non-exact incircle when the initial CDT is built."""
    mesh = aftmesh.generate(triangle.get_data("double_hex"), greedy=True, split_boundary=False)
    assert dc.non_delaunay_edges(mesh) == []


def test_regression_greedy_not_cdt_regular_polygon():
    """The same on a regular 13-gon (all vertices nearly cocircular)."""
    t = 2 * np.pi * np.arange(13) / 13
    mesh = aftmesh.generate(np.c_[np.cos(t), np.sin(t)], greedy=True, split_boundary=False)
    assert len(mesh.triangles) == 11
    assert dc.non_delaunay_edges(mesh) == []


# Boundary edges that are neither horizontal nor vertical are cut into pieces whose
# ends are only nearly collinear; inserting those pieces into the CDT goes wrong.
DIAMOND = [(0.0, 1.0), (-1.0, 0.0), (0.0, -1.0), (1.0, 0.0)]


def test_regression_slanted_edges_kernel_error():
    """A square turned by 45 degrees, constant size: KernelError (code -4)."""
    mesh = aftmesh.generate(np.array(DIAMOND), 0.15)
    assert_valid(mesh, dc.shapely_case("diamond", Polygon(DIAMOND), 0.15))


def test_regression_slanted_edge_false_crossing():
    """A plain right triangle: CrossingSegmentsError between two pieces of its own
    hypotenuse, which do not cross."""
    ring = [(0.0, 0.0), (10.0, 3.0), (10.0, 0.0)]
    mesh = aftmesh.generate(np.array(ring), 0.3)
    assert_valid(mesh, dc.shapely_case("tri", Polygon(ring), 0.3))


def test_regression_slanted_edge_overlapping_segments():
    """Right triangle with legs 3 and 1, size 0.1: the hypotenuse's pieces overlap
    (segments 7.95 long in all for a perimeter of 7.16) with zero-area triangles
    between them; check_mesh lets it through."""
    ring = [(0.0, 0.0), (3.0, 1.0), (3.0, 0.0)]
    mesh = aftmesh.generate(np.array(ring), 0.1)
    total = np.linalg.norm(np.diff(segment_coords(mesh), axis=1)[:, 0], axis=1).sum()
    assert total == pytest.approx(4 + np.sqrt(10), rel=1e-12)
    assert_valid(mesh, dc.shapely_case("tri", Polygon(ring), 0.1))


def test_regression_slanted_edges_inverted_triangles():
    """The diamond from cos/sin with a graded size: two triangles are clockwise."""
    t = np.pi / 2 * np.arange(4) + np.pi / 2
    ring = np.c_[np.cos(t), np.sin(t)]
    mesh = aftmesh.generate(ring, graded)
    assert (dc.orient_signs(np.asarray(mesh.points), np.asarray(mesh.triangles)) > 0).all()
    assert_valid(mesh, dc.shapely_case("diamond", Polygon(ring), 0.15))


def test_converging_fronts_in_a_disc_merge_their_rows(checked):
    """A disc as a 256-gon meshed at its edges' length: the fronts from the circle
    converge, and each ring of the mesh must lose points.  The rows used to keep all
    256 points until they were compressed to 0.6 of the size (mean radius ratio 0.981,
    8 % more triangles than the disc's area asks for); now they merge points as soon
    as their edges are shorter than 0.8 of the size (front.pxi, CONVERGING_EDGE), or
    give way to one lattice before that (lattice.pxi)."""
    disc = Point(0, 0).buffer(1.0, 64)
    h = 2.0 * np.sin(np.pi / 256)
    mesh = checked(aftmesh.generate(disc, h), domain_area=disc.area)
    ideal = disc.area / (np.sqrt(3.0) / 4.0 * h * h)
    assert abs(len(mesh.triangles) / ideal - 1.0) < 0.05
    assert mesh.quality()["radius_ratio_mean"] > 0.985


@pytest.mark.parametrize(
    ("name", "domain", "h", "turn", "floor"),
    [
        ("disc", Point(0, 0).buffer(1.0, 64), 2.0 * np.sin(np.pi / 256), 0.0, 0.9975),
        ("disc", Point(0, 0).buffer(1.0, 64), 2.0 * np.sin(np.pi / 256), 29.0, 0.9975),
        ("disc", Point(0, 0).buffer(1.0, 64), 2.0 * np.sin(np.pi / 256), 47.0, 0.9975),
        (
            "annulus",
            Point(0, 0).buffer(1.0, 64).difference(Point(0, 0).buffer(0.5, 32)),
            0.0245,
            0.0,
            0.995,
        ),
    ],
)
def test_converging_rows_give_way_to_one_lattice(checked, name, domain, h, turn, floor):
    """Under one constant size, the rows from a circle that curves round the unmeshed
    region shorten layer by layer.  Kept, each stretch of the rim grew its own lattice
    and the seams between them held the poor triangles (mean radius ratio 0.9891 on
    the disc, 0.9842 on the annulus).  Snapped to one lattice through input vertex 0
    once their edges were shorter than 0.97 of the size, the disc reached 0.9921-0.9935
    over turns of 0-71 degrees (the turn moves the lattice against the rim), with
    smallest angles down to 28 degrees.  From the second row on, R moves to a lattice
    with a point at the centroid, and a lattice point that is refused gives way to the
    plain R rather than to S (lattice.pxi): 0.9977-0.9980 (Gmsh: 0.9972), the annulus
    0.9955, no angle below 44 degrees."""
    domain = affinity.rotate(domain, turn, origin=(0.1, 0.2))
    mesh = checked(aftmesh.generate(domain, h), domain_area=domain.area)
    assert mesh.quality()["min_angle"] > 40.0, name
    assert mesh.quality()["radius_ratio_mean"] > floor, name
