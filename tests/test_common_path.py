"""generate's common case (one compiled call, aftmesh._common) makes exactly the mesh
the stages make, and hands every other case to them.

Each test meshes the same input twice, once as generate does and once with the common
case switched off, and compares every array and every reported count."""

import math

import numpy as np
import pytest
import shapely
from domain_cases import (
    nested_multipolygons,
    polygons_with_circular_holes,
    shapely_cases,
    star_polygons,
    triangle_sample,
)
from hypothesis import given
from hypothesis import strategies as st
from shapely.geometry import MultiPolygon, Polygon, box

import aftmesh
import aftmesh._common as common
from aftmesh import inputs
from aftmesh.errors import InvalidDomainError, InvalidInputError, InvalidSizeError

MESH_ARRAYS = ("points", "triangles", "neighbors", "segments", "regions")
FIELD_ARRAYS = ("points", "user", "graded", "triangles", "neighbors")


class Taken:
    """Counts the calls the common case took (returned a mesh) and declined."""

    def __init__(self, monkeypatch):
        self.taken = self.declined = 0
        original = common.common_case

        def counting(*args):
            mesh = original(*args)
            if mesh is None:
                self.declined += 1
            else:
                self.taken += 1
            return mesh

        monkeypatch.setattr(common, "common_case", counting)


def _by_stages(monkeypatch, domain, size, **kw):
    with monkeypatch.context() as m:
        m.setattr(common, "applies", lambda *args: False)
        return aftmesh.generate(domain, size, **kw)


def assert_same_mesh(a, b):
    for name in MESH_ARRAYS + ("segment_sources", "segment_markers"):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            assert x.dtype == y.dtype and np.array_equal(x, y), name
    fa, fb = a.info["size_field"], b.info["size_field"]
    assert fa.constant == fb.constant and fa.rate == fb.rate and fa.reach == fb.reach
    for name in FIELD_ARRAYS:
        assert np.array_equal(getattr(fa, name), getattr(fb, name)), name
    skip = {"timing", "size_field"}
    assert {k: v for k, v in a.info.items() if k not in skip} == {
        k: v for k, v in b.info.items() if k not in skip
    }
    assert set(a.info["timing"]) == set(b.info["timing"])


def _region_areas(mesh, regions) -> np.ndarray:
    p, t = mesh.points, mesh.triangles
    a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
    area = 0.5 * ((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
    return np.array([area[mesh.regions == r].sum() for r in regions])


def _compare(monkeypatch, domain, size, checked=None, **kw):
    taken = Taken(monkeypatch)
    mesh = aftmesh.generate(domain, size, **kw)
    if checked is not None:
        checked(mesh)
    assert_same_mesh(mesh, _by_stages(monkeypatch, domain, size, **kw))
    return taken


# a strip whose short edges need a background field, and a square whose edges do not
STRIP = Polygon([(0, 0), (4, 0), (4, 0.3), (2.05, 0.3), (2, 0.31), (1.95, 0.3), (0, 0.3)])
OPTIONS = [
    {},
    {"min_angle": None},
    {"min_angle": 33.0},
    {"smooth": 0},
    {"order": "longest"},
    {"order": "oldest"},
    {"greedy": True},
    {"swaps": False},
    {"gradation": 1.0},
    {"gradation": 2.5},
    {"min_area": 1e-3},
    {"close_factor": 0.3},
    {"max_triangles": 200},
    {"progress": False},
    {"tolerance": 1e-9},
    {"split_boundary": False},
    {"split_boundary": False, "min_angle": 33.0},
    {"split_boundary": False, "slide_boundary": False, "smooth": 2},
]


@pytest.mark.parametrize("kw", OPTIONS, ids=lambda kw: ",".join(kw) or "defaults")
@pytest.mark.parametrize("domain", [STRIP, box(0, 0, 1, 1)], ids=["strip", "square"])
def test_common_case_makes_the_stages_mesh_under_every_option(monkeypatch, checked, domain, kw):
    taken = _compare(monkeypatch, domain, 0.1, checked, **kw)
    assert taken.taken == 1


@pytest.mark.parametrize("case", shapely_cases(), ids=repr)
def test_common_case_makes_the_stages_mesh_on_the_shapely_cases(monkeypatch, checked, case):
    _compare(monkeypatch, case.domain, case.size, checked)


@pytest.mark.parametrize("case", shapely_cases(), ids=repr)
def test_common_case_keeps_input_edges_whole_as_the_stages_do(monkeypatch, checked, case):
    # split_boundary=False: no discretization, the kept-whole sizes at the vertices,
    # no segment split by the minimum-angle pass; taken wherever split edges are
    with monkeypatch.context() as m:
        whole = _compare(m, case.domain, case.size, checked, split_boundary=False).taken
    with monkeypatch.context() as m:
        split = _compare(m, case.domain, case.size).taken
    assert whole == split


@pytest.mark.parametrize("case", shapely_cases(), ids=repr)
def test_common_case_takes_the_size_from_the_edges_as_the_stages_do(monkeypatch, checked, case):
    # size=None (the default): the input edges' lengths, graded; taken wherever a
    # number size is (touching parts are classified by probes either way)
    with monkeypatch.context() as m:
        by_edges = _compare(m, case.domain, None, checked).taken
    with monkeypatch.context() as m:
        by_number = _compare(m, case.domain, case.size).taken
    assert by_edges == by_number


@pytest.mark.parametrize("split", [True, False], ids=["split", "whole"])
@pytest.mark.parametrize("name", ["A", "face", "la", "double_hex"])
def test_common_case_makes_the_stages_mesh_on_triangle_samples(monkeypatch, checked, name, split):
    case = triangle_sample(name)
    _compare(monkeypatch, case.domain, case.size, checked, split_boundary=split)


def test_common_case_takes_rings_dicts_holes_and_hole_points(monkeypatch):
    ring = np.array([[0, 0], [2, 0], [2, 1], [0, 1.0]])
    assert _compare(monkeypatch, ring, 0.2).taken == 1
    square = {"vertices": ring, "segments": [[0, 1], [1, 2], [2, 3], [3, 0]]}
    assert _compare(monkeypatch, square, 0.2).taken == 1
    holed = box(0, 0, 2, 2).difference(box(0.5, 0.5, 1, 1))
    assert _compare(monkeypatch, holed, 0.2).taken == 1
    assert _compare(monkeypatch, FRAMED, 0.2).taken == 1  # Triangle's hole points
    parts = [box(0, 0, 1, 1), box(1, 0, 2, 1)]
    assert _compare(monkeypatch, parts, 0.2).taken == 1  # two regions: by probes


@pytest.mark.parametrize("split", [True, False], ids=["split", "whole"])
def test_common_case_meshes_free_vertices_as_the_stages_do(monkeypatch, checked, split):
    # a dict's vertices on no segment (Triangle's free points) are meshed where they
    # are and ask for no size: the field is built on the others, in their order
    ring = [[0, 0], [2, 0], [2, 1], [0, 1.0]]
    free = {
        "vertices": [[0.7, 0.5]] + ring + [[1.31, 0.42], [1.5, 0.75]],
        "segments": [[1, 2], [2, 3], [3, 4], [4, 1]],
    }
    for size in (0.2, None, 0.05):
        taken = _compare(monkeypatch, free, size, checked, split_boundary=split)
        assert taken.taken == 1
    mesh = aftmesh.generate(free, 0.2, split_boundary=split)
    for p in ([0.7, 0.5], [1.31, 0.42], [1.5, 0.75]):
        assert (mesh.points == p).all(axis=1).sum() == 1


# Triangle's way: a frame and a square inside it, with a hole point in the square
INNER = [[0.8, 0.4], [1.2, 0.4], [1.2, 0.6], [0.8, 0.6]]
FRAMED = {
    "vertices": [[0, 0], [2, 0], [2, 1], [0, 1.0]] + INNER,
    "segments": [[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 7], [7, 4]],
    "holes": [[1.0, 0.5]],
}


def test_common_case_gives_region_points_their_markers(monkeypatch, checked):
    marked = {**FRAMED, "holes": [], "regions": [[0.1, 0.1, 7], [1.0, 0.5, -3]]}
    assert _compare(monkeypatch, marked, 0.2, checked).taken == 1
    mesh = aftmesh.generate(marked, 0.2)
    assert set(np.unique(mesh.regions)) == {7, -3}
    assert np.allclose(_region_areas(mesh, [7, -3]), [2.0 - 0.08, 0.08], rtol=1e-12)
    both = {**FRAMED, "regions": [[0.1, 0.1, 5]]}  # the square a hole, the frame region 5
    assert _compare(monkeypatch, both, 0.2, checked).taken == 1


@pytest.mark.parametrize(
    "where, message",
    [
        ({"holes": [[0.8, 0.5]]}, r"holes\[0\] = \(0\.8, 0\.5\) lies on a segment"),
        ({"holes": [[1.2, 0.6]]}, r"holes\[0\] = \(1\.2, 0\.6\) lies on a segment"),
        ({"holes": [[3.0, 0.5]]}, r"holes\[0\] = \(3, 0\.5\) is not inside the domain"),
        ({"regions": [[1.0, 0.5, 1], [2.0, 0.0, 2]]}, r"regions\[1\] = \(2, 0\) lies on"),
    ],
)
def test_common_case_leaves_misplaced_points_to_the_stages_errors(monkeypatch, where, message):
    taken = Taken(monkeypatch)
    with pytest.raises(InvalidDomainError, match=message):
        aftmesh.generate({**FRAMED, **where}, 0.2)
    assert taken.declined == 1 and taken.taken == 0


def test_common_case_leaves_fractional_region_markers_to_the_stages(monkeypatch):
    taken = Taken(monkeypatch)
    with pytest.raises(InvalidInputError, match=r"regions\[0\] has marker 1\.5"):
        aftmesh.generate({**FRAMED, "regions": [[0.1, 0.1, 1.5]]}, 0.2)
    assert taken.declined == taken.taken == 0


@st.composite
def dicts_with_hole_points(draw):
    """polygons_with_circular_holes as Triangle's dict: each disc a hole point at its
    centre, or a region point with a marker, and maybe a marker for the square."""
    poly = draw(polygons_with_circular_holes())
    rings = [poly.exterior] + list(poly.interiors)
    vertices, segments, holes, regions = [], [], [], []
    for ring in rings:
        xy = np.asarray(ring.coords)[:-1]
        k = len(vertices)
        vertices.extend(xy.tolist())
        segments.extend([k + i, k + (i + 1) % len(xy)] for i in range(len(xy)))
    for ring in poly.interiors:
        centre = list(Polygon(ring).centroid.coords[0])
        if draw(st.booleans()):
            holes.append(centre)
        else:
            regions.append(centre + [draw(st.integers(-5, 5))])
    if draw(st.booleans()):
        regions.append([0.02, 0.02, draw(st.integers(-5, 5))])
    return {"vertices": vertices, "segments": segments, "holes": holes, "regions": regions}


@given(dicts_with_hole_points(), st.sampled_from([0.05, 0.2, None]), st.booleans())
def test_common_case_makes_the_stages_mesh_with_hole_and_region_points(domain, size, split):
    with pytest.MonkeyPatch.context() as monkeypatch:
        assert _compare(monkeypatch, domain, size, split_boundary=split).taken == 1


def test_common_case_declines_what_only_the_stages_report(monkeypatch):
    # the boundary alone above max_triangles, formula (3) above it, the count
    # estimate above the limit: the stages' messages
    taken = Taken(monkeypatch)
    with pytest.raises(InvalidSizeError, match="boundary alone"):
        aftmesh.generate(box(0, 0, 1, 1), 0.1, max_triangles=1)
    with pytest.raises(InvalidSizeError, match="formula"):
        aftmesh.generate(box(0, 0, 1, 1), 0.1, max_triangles=20)
    with pytest.raises(InvalidSizeError, match="asks for about"):
        aftmesh.generate(box(0, 0, 1, 1), 1e-6)
    assert taken.declined == 3 and taken.taken == 0


def test_common_case_with_edges_kept_whole_declines_what_only_the_stages_report(monkeypatch):
    # formula (3) above max_triangles and the count estimate above the limit: the
    # stages' messages (kept whole, no discretization refuses a boundary first)
    taken = Taken(monkeypatch)
    with pytest.raises(InvalidSizeError, match="formula"):
        aftmesh.generate(STRIP, 0.1, max_triangles=3, split_boundary=False)
    with pytest.raises(InvalidSizeError, match="asks for about"):
        aftmesh.generate(box(0, 0, 1, 1), 1e-6, split_boundary=False)
    assert taken.declined == 2 and taken.taken == 0


def test_common_case_takes_boundaries_longer_than_the_cached_round_keys(monkeypatch, checked):
    # more boundary points than _order.CACHED_ROUNDS, in the background and after the
    # discretization: the compiled call draws the longer keys the stages draw
    from aftmesh._order import CACHED_ROUNDS

    n = CACHED_ROUNDS + 500
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    ring = np.c_[np.cos(t), np.sin(t) * (1.0 + 0.02 * np.cos(7.0 * t))]
    edge = float(np.min(np.hypot(*(np.roll(ring, -1, axis=0) - ring).T)))
    assert _compare(monkeypatch, Polygon(ring), 4.0 * edge, checked).taken == 1


def test_common_case_declines_a_large_mesh_only_where_a_progress_bar_may_show(monkeypatch, checked):
    import aftmesh._stages as stages

    class Terminal:
        def isatty(self):
            return True

        def write(self, s):
            pass

        def flush(self):
            pass

    monkeypatch.setattr(stages, "PROGRESS_MIN_TRIANGLES", 50)  # "large" from 50 on
    # standard error not a terminal (captured): no bar is possible, the call is taken
    assert _compare(monkeypatch, box(0, 0, 1, 1), 0.05, checked).taken == 1
    terminal = Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    taken = Taken(monkeypatch)
    checked(aftmesh.generate(box(0, 0, 1, 1), 0.05))
    assert taken.declined == 1 and taken.taken == 0  # the stages may draw the bar
    assert isinstance(stages._progress_callback(None, 51), stages._ProgressBar)
    taken = Taken(monkeypatch)
    checked(aftmesh.generate(box(0, 0, 1, 1), 0.05, progress=False))
    assert taken.taken == 1


def test_no_standard_error_draws_no_bar_and_raises_nothing(monkeypatch, checked):
    # sys.stderr is None under pythonw and in some services: no bar can show there,
    # and neither path may call isatty on it
    import aftmesh._stages as stages

    monkeypatch.setattr(stages, "PROGRESS_MIN_TRIANGLES", 50)  # "large" from 50 on
    monkeypatch.setattr("sys.stderr", None)
    assert stages._progress_callback(None, 51) is None
    taken = Taken(monkeypatch)
    checked(aftmesh.generate(box(0, 0, 1, 1), 0.05))
    assert taken.taken == 1  # no bar can show: the compiled call is taken
    checked(aftmesh.generate(box(0, 0, 1, 1), lambda x, y: 0.05 + 0 * x))  # the stages


def test_common_case_takes_plain_numbers_none_and_fields(monkeypatch):
    taken = _compare(monkeypatch, box(0, 0, 1, 1), np.float64(0.25))
    assert taken.taken == 0
    taken = _compare(monkeypatch, box(0, 0, 1, 1), 1)
    assert taken.taken == 1
    taken = _compare(monkeypatch, box(0, 0, 1, 1), lambda x, y: 0.2 + 0 * x)
    assert taken.taken == 1  # the stages' field of the callable, made first
    taken = _compare(monkeypatch, STRIP, None)
    assert taken.taken == 1
    taken = _compare(monkeypatch, box(0, 0, 1, 1), [0.2])  # per region: a field too
    assert taken.taken == 1
    for bad in (0, 0.0, -1.0, math.inf, math.nan):
        taken = Taken(monkeypatch)
        with pytest.raises(InvalidSizeError, match="finite and positive"):
            aftmesh.generate(STRIP, bad)
        assert taken.taken == taken.declined == 0  # the stages' message


def _graded(x, y):
    # finer towards the origin, by a factor of 20 over the unit square
    return 0.01 + 0.2 * np.hypot(x, y)


@pytest.mark.parametrize("split", [True, False], ids=["split", "whole"])
@pytest.mark.parametrize(
    "domain", [STRIP, box(0, 0, 1, 1), FRAMED], ids=["strip", "square", "dict"]
)
def test_common_case_makes_the_stages_mesh_with_a_size_callable(
    monkeypatch, checked, domain, split
):
    calls = []

    def counted(x, y):
        calls.append(len(x))
        return _graded(x, y)

    assert _compare(monkeypatch, domain, counted, checked, split_boundary=split).taken == 1
    # each generate call builds the callable's field once: the stages' rounds
    once = len(calls) // 2
    assert once > 0 and calls[:once] == calls[once:]
    mesh = aftmesh.generate(domain, _graded, split_boundary=split)
    field = mesh.info["size_field"]
    assert not field.is_constant and field.rate == pytest.approx(0.3)


def test_common_case_takes_a_size_field_as_it_is(monkeypatch, checked):
    # a field made before (a partitioned mesh's parts get the whole domain's): used
    # as it is, constant or not, without deriving anything from the edges
    graded = aftmesh.generate(STRIP, _graded).info["size_field"]
    constant = aftmesh.generate(box(0, 0, 1, 1), 0.1).info["size_field"]
    for field in (graded, constant):
        for split in (True, False):
            taken = _compare(monkeypatch, STRIP, field, checked, split_boundary=split)
            assert taken.taken == 1
    assert aftmesh.generate(STRIP, graded).info["size_field"] is graded


@given(star_polygons(), st.sampled_from([0.05, 0.2, 1.0, None, _graded]), st.booleans())
def test_common_case_makes_the_stages_mesh_on_random_polygons(poly, size, split):
    with pytest.MonkeyPatch.context() as monkeypatch:
        _compare(monkeypatch, poly, size, split_boundary=split)


@given(st.floats(1e-9, 1e-2), st.floats(0.01, 0.5), st.booleans())
def test_common_case_makes_the_stages_mesh_next_to_a_short_edge(chamfer, size, split):
    corner = shapely.Polygon([(0, 0), (1, 0), (1, 1 - chamfer), (1 - chamfer, 1), (0, 1)])
    with pytest.MonkeyPatch.context() as monkeypatch:
        _compare(monkeypatch, corner, size, split_boundary=split)


@given(
    polygons_with_circular_holes(), st.sampled_from([0.03, 0.1, 0.4, None, _graded]), st.booleans()
)
def test_common_case_makes_the_stages_mesh_on_random_polygons_with_holes(poly, size, split):
    with pytest.MonkeyPatch.context() as monkeypatch:
        _compare(monkeypatch, poly, size, split_boundary=split)


def test_common_case_classifies_holes_touching_the_exterior_and_each_other(monkeypatch, checked):
    outer = box(0, 0, 4, 4)
    touching = Polygon(
        outer.exterior.coords,
        [[(0, 1), (1, 2), (1, 1)], [(1, 2), (2, 3), (2, 2)], [(3, 3), (4, 4), (3.5, 3)]],
    )
    assert touching.is_valid
    assert _compare(monkeypatch, touching, 0.2, checked).taken == 1


def _voronoi(n: int, seed: int) -> list:
    rng = np.random.default_rng(seed)
    cells = shapely.get_parts(
        shapely.voronoi_polygons(shapely.MultiPoint(rng.random((n, 2))), extend_to=box(0, 0, 1, 1))
    )
    return list(shapely.intersection(cells, box(0, 0, 1, 1)))


# lists of regions, whose pieces the compiled call classifies by the stages' probes: a
# tiling; four frames around an uncovered square (a hole no region holds); a region
# in another's hole; a region of two parts; Voronoi parcels
FRAME = [box(0, 0, 3, 1), box(2, 1, 3, 3), box(0, 2, 2, 3), box(0, 1, 1, 2)]
REGION_LISTS = {
    "tiling": [box(i, j, i + 1, j + 1) for i in range(3) for j in range(2)],
    "frame": FRAME,
    "inclusion": [box(0, 0, 4, 4).difference(box(1, 1, 2, 2)), box(1, 1, 2, 2)],
    "two parts": [MultiPolygon([box(0, 0, 1, 1), box(2, 0, 3, 1)]), box(1, 0, 2, 1)],
    "voronoi": _voronoi(12, seed=5),
}


@pytest.mark.parametrize("kw", [{}, {"split_boundary": False}, {"min_angle": None}],
                         ids=["defaults", "whole", "no min angle"])  # fmt: skip
@pytest.mark.parametrize("name", list(REGION_LISTS))
def test_common_case_makes_the_stages_mesh_on_lists_of_regions(monkeypatch, checked, name, kw):
    regions = REGION_LISTS[name]
    size = 0.05 if name == "voronoi" else 0.3
    assert _compare(monkeypatch, regions, size, checked, **kw).taken == 1
    mesh = aftmesh.generate(regions, size, **kw)
    areas = _region_areas(mesh, range(len(regions)))
    assert np.allclose(areas, [g.area for g in regions], rtol=1e-9)


def test_common_case_takes_lists_of_regions_at_a_size_callable_per_region_or_none(
    monkeypatch, checked
):
    for size in (_graded, None):
        assert _compare(monkeypatch, REGION_LISTS["tiling"], size, checked).taken == 1
    # a size per region: the field of the regions' polygons, made first as a callable's
    for sizes in ([0.2, 0.3, 0.4, 0.5], (0.2, 0.3, 0.4, 0.5), np.array([0.2, 0.3, 0.4, 0.5])):
        assert _compare(monkeypatch, FRAME, sizes, checked).taken == 1
    with pytest.raises(InvalidSizeError):
        aftmesh.generate(FRAME, [0.2, 0.3])  # one size short: the stages' message


def test_common_case_leaves_a_list_of_regions_without_area_to_the_stages(monkeypatch):
    taken = Taken(monkeypatch)
    with pytest.raises(InvalidSizeError, match="max_triangles"):
        aftmesh.generate(REGION_LISTS["tiling"], 0.3, max_triangles=5)
    assert taken.declined == 1 and taken.taken == 0


# constraint lines and points inside polygons: classified by the stages' probes too
SQUARE4 = box(0, 0, 4, 4)
WITH_LINES = {
    "line inside": [SQUARE4, shapely.LineString([(1, 1), (3, 2.5)])],
    "line across": [SQUARE4, shapely.LineString([(0, 2), (4, 2)])],
    "line from the boundary": [SQUARE4, shapely.LineString([(0, 1), (2, 2)])],
    "polyline": [SQUARE4, shapely.LineString([(0.5, 0.5), (1.5, 3), (3, 1), (3.5, 3.5)])],
    "points": [SQUARE4, shapely.Point(1, 1), shapely.Point(2.5, 3.1)],
    "crossing lines": [
        SQUARE4,
        shapely.LineString([(1, 1), (3, 3)]),
        shapely.LineString([(1, 3), (3, 1)]),
    ],
    "closed line": [SQUARE4, shapely.LineString([(1, 1), (3, 1), (3, 3), (1, 3), (1, 1)])],
    "hole and line": [
        SQUARE4.difference(box(1, 1, 2, 2)),
        shapely.LineString([(2, 2), (3.5, 3.5)]),
        shapely.Point(3, 1),
    ],
    "parts and line": [
        MultiPolygon([box(0, 0, 1, 1), box(2, 0, 3, 1)]),
        shapely.LineString([(0.2, 0.5), (0.8, 0.5)]),
    ],
}


@pytest.mark.parametrize("split", [True, False], ids=["split", "whole"])
@pytest.mark.parametrize("size", [0.3, None, _graded], ids=["number", "none", "callable"])
@pytest.mark.parametrize("name", list(WITH_LINES))
def test_common_case_makes_the_stages_mesh_with_lines_and_points(
    monkeypatch, checked, name, size, split
):
    collection = shapely.GeometryCollection(WITH_LINES[name])
    assert _compare(monkeypatch, collection, size, checked, split_boundary=split).taken == 1


# islands in lakes in islands, beside a square apart: four parts, each its own region
LAKES = MultiPolygon(
    [
        Polygon([(0, 0), (10, 0), (10, 10), (0, 10)], [[(2, 2), (8, 2), (8, 8), (2, 8)]]),
        Polygon([(3, 3), (7, 3), (7, 7), (3, 7)], [[(4, 4), (6, 4), (6, 6), (4, 6)]]),
        box(4.5, 4.5, 5.5, 5.5),
        box(12, 0, 13, 1),
    ]
)


def test_common_case_gives_nested_parts_the_regions_the_probes_give(monkeypatch, checked):
    taken = _compare(monkeypatch, LAKES, 0.4, checked)
    assert taken.taken == 1
    mesh = aftmesh.generate(LAKES, 0.4)
    areas = _region_areas(mesh, range(len(LAKES.geoms)))
    assert np.allclose(areas, [g.area for g in LAKES.geoms], rtol=1e-12)


@given(nested_multipolygons(), st.sampled_from([0.05, 0.2, None]), st.booleans())
def test_common_case_makes_the_stages_mesh_on_nested_multipolygons(multi, size, split):
    with pytest.MonkeyPatch.context() as monkeypatch:
        taken = _compare(monkeypatch, multi, size, split_boundary=split)
    assert taken.taken + taken.declined == 1
    if inputs.proved_polygon(multi) is not None:
        assert taken.taken == 1


def test_common_case_declines_pieces_that_do_not_nest_as_said(monkeypatch, checked):
    # a Domain whose ring_polygon puts a polygon's hole in another polygon: the
    # piece between the two rings is bounded by two polygons' rings, so the compiled
    # call declines and the stages classify by probes
    holed = Polygon([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (3, 1), (3, 3), (1, 3)]])
    beside = box(5, 0, 6, 1)
    multi = MultiPolygon([holed, beside])
    proved = inputs.proved_polygon

    def mislabelled(domain):
        dom = proved(domain)
        dom.ring_polygon = np.array([0, 1, 1], dtype=np.int32)
        return dom

    monkeypatch.setattr(inputs, "proved_polygon", mislabelled)
    taken = _compare(monkeypatch, multi, 0.5, checked)
    assert taken.declined == 1 and taken.taken == 0


def test_generate_common_refuses_a_ring_polygon_that_misses_a_source():
    from aftmesh._kernel import generate_common

    ring = np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]])
    segments = np.array([[0, 1], [1, 2], [2, 3], [3, 0]], dtype=np.int32)
    source = np.arange(4, dtype=np.int32)
    edge_source = np.array([0, 0, 0, 1], dtype=np.int32)
    # size, gradation, area, round keys, rules, most pieces, progress limit, order,
    # max_triangles, min_area, close_factor; swaps, greedy, smoothing rounds, slides,
    # min_angle, scaffold
    numbers = (0.5, 1.5, 1.0, None, common._RULES, 100.0, 1e9, 0, -1, None, 0.5)
    switches = (True, False, 3, True, 0.0, False)
    wrong = np.zeros(1, dtype=np.int32)  # one ring, but edge 3 is of source 1
    points = (None, None, None)  # no hole or region points
    with pytest.raises(ValueError, match=r"edge_source\[3\] = 1 names no ring"):
        generate_common(
            ring, segments, source, edge_source, True, wrong, *points, *numbers, *switches
        )


def test_generate_common_refuses_region_points_without_one_id_each():
    from aftmesh._kernel import generate_common

    ring = np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]])
    segments = np.array([[0, 1], [1, 2], [2, 3], [3, 0]], dtype=np.int32)
    source = np.arange(4, dtype=np.int32)
    numbers = (0.5, 1.5, 1.0, None, common._RULES, 100.0, 1e9, 0, -1, None, 0.5)
    switches = (True, False, 3, True, 0.0, False)
    seeds = np.array([[0.5, 0.5], [0.2, 0.2]])
    with pytest.raises(ValueError, match="seed_ids"):
        generate_common(
            ring, segments, source, source * 0, False, None, None, seeds,
            np.zeros(1, dtype=np.int32), *numbers, *switches,
        )  # fmt: skip
