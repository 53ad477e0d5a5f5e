"""Segment provenance and named boundary parts: ``Mesh.segment_sources``,
``generate(boundary_tags=...)``, ``Mesh.segment_tags`` / ``tag_names`` /
``boundary_facets``."""

import numpy as np
import pytest
from shapely.geometry import GeometryCollection, LineString, Point, Polygon, box

import aftmesh
from aftmesh.errors import InvalidOptionError
from aftmesh.tags import resolve_boundary_tags

# box(0, 0, 2, 1) is the ring (2,0) -> (2,1) -> (0,1) -> (0,0): edges 0..3 are
# right, top, left, bottom
SIDES = {"right": 0, "top": 1, "left": 2, "bottom": 3}
SELECT = {
    "left": lambda x, y: x == 0,
    "right": lambda x, y: x == 2,
    "bottom": lambda x, y: y == 0,
    "top": lambda x, y: y == 1,
}


def _on(mesh, axis, value):
    """Which segments lie on the line coordinate[axis] == value."""
    return (mesh.points[mesh.segments][:, :, axis] == value).all(axis=1)


def test_box_with_named_sides(checked):
    domain = box(0, 0, 2, 1)
    mesh = checked(aftmesh.generate(domain, 0.1, boundary_tags=SELECT), domain_area=2.0)
    assert mesh.tag_names == {"left": 1, "right": 2, "bottom": 3, "top": 4}
    assert len(mesh.segments) > 40  # every side was split into pieces
    for name, axis, value in [
        ("left", 0, 0.0),
        ("right", 0, 2.0),
        ("bottom", 1, 0.0),
        ("top", 1, 1.0),
    ]:
        on = _on(mesh, axis, value)
        assert on.sum() >= 10
        assert (mesh.segment_tags[on] == mesh.tag_names[name]).all()
        assert np.array_equal(mesh.boundary_facets(name), np.flatnonzero(on))
        assert (mesh.segment_sources[on] == SIDES[name]).all()
    assert (mesh.segment_tags > 0).all()


def test_selectors_by_input_edge_index_and_callable_called_once(checked):
    calls = []

    def left(x, y):
        calls.append(len(x))
        return x == 0

    mesh = checked(
        aftmesh.generate(box(0, 0, 2, 1), 0.25, boundary_tags={"left": left, "ends": [0, 3]}),
        domain_area=2.0,
    )
    assert calls == [4]
    ends = mesh.boundary_facets("ends")
    assert set(mesh.segment_sources[ends].tolist()) == {0, 3}
    untagged = mesh.segment_tags == 0
    assert (mesh.segment_sources[untagged] == 1).all() and untagged.any()


def test_an_edge_selected_twice_names_both_and_the_edge():
    with pytest.raises(
        InvalidOptionError,
        match=r"input edge 2 \(the polygon, exterior ring\)"
        r".*both boundary_tags 'west' and 'left'",
    ):
        aftmesh.generate(box(0, 0, 2, 1), 0.25, boundary_tags={"west": [2], "left": SELECT["left"]})


@pytest.mark.parametrize(
    "tags, match",
    [
        ({"a": [7]}, "input edge 7, but the input edges are numbered 0..3"),
        ({"a": lambda x, y: np.ones((len(x), 2), bool)}, "boolean array of length 4"),
        ({"a": lambda x, y: x}, "boolean array"),
        ({"a": "left"}, "callable f\\(x, y\\) or a sequence"),
        ([("a", [0])], "mapping"),
        ({1: [0]}, "names must be strings"),
    ],
)
def test_bad_boundary_tags_are_refused(tags, match):
    with pytest.raises(InvalidOptionError, match=match):
        aftmesh.generate(box(0, 0, 2, 1), 0.25, boundary_tags=tags)


def test_boundary_facets_unknown_name_lists_the_names_and_int_uses_markers():
    mesh = aftmesh.generate(
        box(0, 0, 2, 1).difference(Point(1, 0.5).buffer(0.2)),
        0.2,
        boundary_tags={"outer": lambda x, y: np.hypot(x - 1, y - 0.5) > 0.3},
    )
    with pytest.raises(InvalidOptionError, match=r"'inner'.*\['outer'\]"):
        mesh.boundary_facets("inner")
    hole = mesh.boundary_facets(1)  # marker 1: the hole's ring
    assert len(hole) > 0 and np.array_equal(hole, np.flatnonzero(mesh.segment_markers == 1))
    assert np.array_equal(
        np.sort(np.concatenate([hole, mesh.boundary_facets("outer")])),
        np.arange(len(mesh.segments)),
    )
    plain = aftmesh.generate(box(0, 0, 1, 1), 0.5)
    assert plain.segment_tags is None and plain.tag_names == {}
    with pytest.raises(InvalidOptionError, match=r"no boundary part named 'x'.*\[\]"):
        plain.boundary_facets("x")


def test_segment_sources_count_ring_edges_then_lines(checked):
    # a square with a hole and a crack: exterior edges 0..3, hole 4..7, line 8..9
    outer = [(0, 0), (4, 0), (4, 4), (0, 4)]
    hole = [(1, 1), (1, 2), (2, 2), (2, 1)]
    crack = LineString([(2.5, 0.5), (3.5, 1.5), (3.5, 3.5)])
    domain = GeometryCollection([Polygon(outer, [hole]), crack])
    mesh = checked(aftmesh.generate(domain, 0.3))
    P, S, src = mesh.points, mesh.segments, mesh.segment_sources
    assert (src >= 0).all()
    rings = [outer + outer[:1], hole + hole[:1]]
    edges = [(a, b) for r in rings for a, b in zip(r[:-1], r[1:])]
    edges += list(zip(crack.coords[:-1], crack.coords[1:]))
    assert set(src.tolist()) == set(range(10))
    for k, (u, v) in enumerate(S):
        a, b = np.array(edges[src[k]], dtype=float)
        for p in (P[u], P[v]):
            # each piece lies on its input edge (within rounding of the split points)
            cross = (b - a)[0] * (p - a)[1] - (b - a)[1] * (p - a)[0]
            assert abs(cross) < 1e-12
            assert -1e-12 <= np.dot(p - a, b - a) <= np.dot(b - a, b - a) + 1e-12


def test_segment_sources_of_a_dict_and_of_cdt_are_segment_indices(checked):
    d = {
        "vertices": [(0, 0), (2, 0), (2, 1), (0, 1)],
        "segments": [(0, 1), (1, 2), (2, 3), (3, 0)],
        "segment_markers": [5, 6, 7, 8],
    }
    mesh = checked(aftmesh.generate(d, 0.2))
    assert np.array_equal(mesh.segment_markers, np.array([5, 6, 7, 8])[mesh.segment_sources])
    m = checked(
        aftmesh.cdt([(0, 0), (1, 0), (1, 1), (0, 1), (0.5, 0)], [(0, 1), (1, 2), (2, 3), (3, 0)])
    )
    assert np.array_equal(np.sort(m.segment_sources), [0, 0, 1, 2, 3])


def test_mesh_fields_are_frozen_int32():
    mesh = aftmesh.generate(
        box(0, 0, 1, 1), 0.5, boundary_tags={"all": lambda x, y: np.isfinite(x)}
    )
    for name in ("segment_sources", "segment_tags"):
        arr = getattr(mesh, name)
        assert arr.dtype == np.int32 and not arr.flags.writeable
    m = aftmesh.Mesh(
        mesh.points,
        mesh.triangles,
        mesh.neighbors,
        mesh.segments,
        mesh.regions,
        segment_sources=[0] * len(mesh.segments),
    )
    assert m.segment_sources.dtype == np.int32 and not m.segment_sources.flags.writeable
    assert m.segment_tags is None and m.tag_names == {}


def test_resolve_boundary_tags_directly():
    mids = np.array([[0.5, 0.0], [1.0, 0.5]])
    tags, names = resolve_boundary_tags({"a": [1], "b": lambda x, y: y == 0}, mids)
    assert tags.tolist() == [2, 1] and names == {"a": 1, "b": 2}
