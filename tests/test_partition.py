"""``aftmesh.generate(domain, size, partitions=k)``: one domain cut into k parts meshed
at once and stitched.  The result has the serial mesh's guarantees: a valid
conforming mesh (check_mesh with the domain's area and input edges), the constrained
Delaunay triangulation of its vertices and input edges (Triangle as the oracle), the
serial mesh's region labels and areas, the appendix's count formula per component."""

from __future__ import annotations

import domain_cases as dc
import numpy as np
import pytest
from shapely.geometry import Point, Polygon, box

import aftmesh
from aftmesh.checks import count_formula
from aftmesh.stitch import lawson_flips


def multi_region():
    regions = [
        box(0, 0, 1, 1),
        box(1, 0, 2, 1),
        box(0, 1, 2, 1.5).difference(Point(1, 1.25).buffer(0.15, quad_segs=4)),
    ]
    return dc.shapely_case("3-regions", regions, 0.05), [0.05, 0.08, 0.06]


def cases():
    holes = dc.many_holes(3, "circle")
    L = dc.l_shape()
    regions, sizes = multi_region()
    return [(holes, 0.1), (L, 0.06), (regions, sizes), (dc.annulus(), 0.05), (dc.spiral(), 0.15)]


# the boundaries split at rounded points (off a slanted edge by an ulp) fail check_mesh's
# exact cover test in the serial mesh as well: for them the test compares the
# partitioned mesh's segments with the serial mesh's
EXACT_COVER = {"9holes-circle", "L", "3-regions"}


CASES = cases()


def region_areas(mesh):
    q = aftmesh.mesh.triangle_quality(mesh.points, mesh.triangles)["area"]
    labels = np.unique(mesh.regions)
    return {int(r): float(q[mesh.regions == r].sum()) for r in labels}


@pytest.mark.parametrize("k", [1, 2, 3, 8])
@pytest.mark.parametrize("case, size", CASES, ids=[c.name for c, _ in CASES])
def test_partitioned_mesh_is_a_valid_cdt_with_the_serial_regions(case, size, k, checked):
    exact = case.name in EXACT_COVER
    mesh = checked(
        aftmesh.generate(case.domain, size, partitions=k),
        domain_area=case.area,
        input_segments=case.edges if exact else None,
    )
    assert "partition_fallback" not in mesh.info
    if k > 1:
        assert mesh.info["partitions"] == k
    dc.assert_cdt(mesh)
    # the same boundary discretization as the serial mesh (the parts share their
    # split points, so they do not slide them; one part is the serial run): the cuts
    # end on its vertices
    serial = aftmesh.generate(case.domain, size, slide_boundary=k == 1)
    assert dc.edge_keys(mesh.points, mesh.segments) == dc.edge_keys(serial.points, serial.segments)
    areas, ref = region_areas(mesh), region_areas(serial)
    assert areas.keys() == ref.keys()
    for r in ref:
        assert areas[r] == pytest.approx(ref[r], rel=1e-9)
    for T, E_b, V_i, m in count_formula(mesh):
        assert T == E_b + 2 * V_i + 2 * (m - 1)
    np.testing.assert_array_equal(
        np.unique(mesh.segment_markers), np.unique(serial.segment_markers)
    )


def test_partitioned_quality_matches_serial_and_cut_triangles_are_good(checked):
    domain = box(0, 0, 2, 1).difference(Point(0.5, 0.5).buffer(0.2))
    serial = checked(aftmesh.generate(domain, 0.01))
    mesh = checked(aftmesh.generate(domain, 0.01, partitions=2))
    q, ref = mesh.quality(), serial.quality()
    assert abs(q["radius_ratio_mean"] - ref["radius_ratio_mean"]) < 0.002
    rr = aftmesh.mesh.triangle_quality(mesh.points, mesh.triangles)["radius_ratio"]
    on_cut = np.isin(mesh.triangles, mesh.info["cut_vertices"]).any(axis=1)
    assert on_cut.sum() > 100
    assert rr[on_cut].min() >= ref["radius_ratio_min"]


def test_parts_meshed_by_dask_tasks_equal_parts_meshed_on_threads(dask_client, checked):
    case, size = CASES[0]
    threads = aftmesh.generate(case.domain, size, partitions=3)
    dask = checked(
        aftmesh.generate(case.domain, size, partitions=3, client=dask_client),
        domain_area=case.area,
        input_segments=case.edges,
    )
    for name in ("points", "triangles", "neighbors", "segments", "regions"):
        np.testing.assert_array_equal(getattr(dask, name), getattr(threads, name))


def test_lawson_flips_make_a_non_delaunay_pair_delaunay(checked):
    # a flat kite split along its long diagonal 0-2: the short one, 1-3, is Delaunay
    P = np.array([(0.0, 0.0), (1.0, -0.2), (2.0, 0.0), (1.0, 0.2)])
    T = np.array([(0, 1, 2), (0, 2, 3)], dtype=np.int32)
    N = np.array([(-1, 1, -1), (-1, -1, 0)], dtype=np.int32)
    outline = {0 * 4 + 1, 1 * 4 + 2, 2 * 4 + 3, 0 * 4 + 3}
    flips = lawson_flips(P, T, N, outline, np.array([(0, 1)]))
    mesh = aftmesh.Mesh(
        points=P,
        triangles=T,
        neighbors=N,
        segments=[(0, 1), (1, 2), (2, 3), (3, 0)],
        regions=[0, 0],
    )
    checked(mesh, domain_area=Polygon(P).area)
    assert flips == 1
    assert {tuple(sorted(t)) for t in T.tolist()} == {(0, 1, 3), (1, 2, 3)}


def triangle_coordinates(mesh) -> set:
    return {tuple(sorted(map(tuple, mesh.points[t].tolist()))) for t in mesh.triangles}


def marked_edges(mesh) -> dict:
    out = {}
    for (u, v), marker in zip(mesh.segments.tolist(), mesh.segment_markers.tolist()):
        a, b = tuple(mesh.points[u].tolist()), tuple(mesh.points[v].tolist())
        out[min(a, b), max(a, b)] = marker
    return out


@pytest.mark.parametrize("backend", ["threads", "dask"])
def test_parts_written_by_their_workers_read_back_as_the_stitched_mesh(
    backend, request, tmp_path, checked
):
    case, sizes = multi_region()
    client = request.getfixturevalue("dask_client") if backend == "dask" else None
    index = aftmesh.generate(
        case.domain, sizes, partitions=3, out=tmp_path / "parts", client=client
    )
    assert index == tmp_path / "parts" / "mesh.pvtu"
    assert len(list((tmp_path / "parts").glob("part*.vtu"))) == 3
    back = checked(
        aftmesh.read_partitioned(tmp_path / "parts"),
        domain_area=case.area,
        input_segments=case.edges,
    )
    stitched = aftmesh.generate(case.domain, sizes, partitions=3)
    # the writer skips the Lawson pass across cuts; here it flips nothing anyway
    assert stitched.info["cut_flips"] == 0
    assert triangle_coordinates(back) == triangle_coordinates(stitched)
    assert marked_edges(back) == marked_edges(stitched)
    assert region_areas(back) == pytest.approx(region_areas(stitched), rel=1e-12)


@pytest.mark.parametrize(
    "options, message",
    [
        ({"partitions": 0}, "partitions must be a positive integer, got 0"),
        ({"partitions": 2.5}, "partitions must be a positive integer"),
        ({"partitions": 2, "greedy": True}, "greedy=True adds no point"),
        ({"partitions": 2, "max_triangles": 100}, "max_triangles cannot be combined"),
    ],
)
def test_bad_partition_options_are_refused_by_name(options, message):
    with pytest.raises(aftmesh.InvalidOptionError, match=message):
        aftmesh.generate(box(0, 0, 1, 1), 0.1, **options)
