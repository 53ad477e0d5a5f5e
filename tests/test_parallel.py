"""``aftmesh.generate_many``: the same meshes as serial ``generate`` calls, by every
backend (threads, serial, a real Dask cluster of 2 worker processes), with a failing
domain in the batch raised with its index or collected in its slot."""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import Point, box

import aftmesh
from aftmesh.parallel import MeshingFailure

BAD_INDEX = 3
BOWTIE = [(0, 0), (1, 1), (1, 0), (0, 1)]  # a self-crossing ring: InvalidDomainError


def batch():
    """Small domains of several input forms, one of them invalid, and their sizes."""
    domains = [
        box(0, 0, 1, 1),
        box(0, 0, 2, 1).difference(Point(0.5, 0.5).buffer(0.2)),
        [box(0, 0, 1, 1), box(1, 0, 2, 1)],
        BOWTIE,
        np.array([(0, 0), (3, 0), (3, 1), (1, 1), (1, 2), (0, 2)], dtype=float),
        Point(5, 5).buffer(1.0),
    ]
    sizes = [0.1, 0.08, [0.1, 0.2], 0.1, 0.15, 0.2]
    return domains, sizes


def assert_same(mesh, ref):
    for name in ("points", "triangles", "neighbors", "segments", "regions", "segment_markers"):
        np.testing.assert_array_equal(getattr(mesh, name), getattr(ref, name), err_msg=name)


@pytest.fixture(scope="module")
def serial_meshes(checked_module):
    domains, sizes = batch()
    out = []
    for i, (d, s) in enumerate(zip(domains, sizes)):
        out.append(None if i == BAD_INDEX else checked_module(aftmesh.generate(d, s)))
    return out


@pytest.fixture(scope="module")
def checked_module():
    from aftmesh.checks import check_mesh

    def run(mesh, **kw):
        check_mesh(mesh, **kw)
        return mesh

    return run


BACKENDS = [{"scheduler": "serial"}, {"scheduler": "threads", "workers": 2}, "dask"]


def backend(kind, request):
    if kind == "dask":
        return {"client": request.getfixturevalue("dask_client")}
    return kind


@pytest.mark.parametrize("kind", BACKENDS, ids=["serial", "threads", "dask"])
def test_generate_many_equals_serial_calls_and_collects_the_failing_domain(
    kind, request, serial_meshes, checked
):
    domains, sizes = batch()
    calls = []
    out = aftmesh.generate_many(
        domains,
        sizes,
        errors="collect",
        progress=lambda done, total: calls.append((done, total)),
        **backend(kind, request),
    )
    assert len(out) == len(domains)
    for i, (mesh, ref) in enumerate(zip(out, serial_meshes)):
        if i == BAD_INDEX:
            assert isinstance(mesh, MeshingFailure) and mesh.index == i
            assert isinstance(mesh.error, aftmesh.InvalidDomainError)
            assert not mesh
        else:
            assert_same(checked(mesh), ref)
            assert not mesh.points.flags.writeable
    assert calls == [(k, len(domains)) for k in range(1, len(domains) + 1)]


@pytest.mark.parametrize("kind", BACKENDS, ids=["serial", "threads", "dask"])
def test_generate_many_raises_the_failing_domains_error_with_its_index(kind, request):
    domains, sizes = batch()
    with pytest.raises(aftmesh.InvalidDomainError, match=f"domain {BAD_INDEX}: ") as info:
        aftmesh.generate_many(domains, sizes, **backend(kind, request))
    assert info.value.index == BAD_INDEX
    assert isinstance(info.value, ValueError)


def test_dask_batches_of_domains_give_the_same_meshes(dask_client, serial_meshes, checked):
    domains, sizes = batch()
    del domains[BAD_INDEX], sizes[BAD_INDEX]
    refs = [m for i, m in enumerate(serial_meshes) if i != BAD_INDEX]
    out = aftmesh.generate_many(domains, sizes, client=dask_client, chunksize=2)
    for mesh, ref in zip(out, refs):
        assert_same(checked(mesh), ref)


def test_dask_without_chunksize_sends_the_domains_in_batches_of_the_automatic_size(
    dask_client, checked
):
    from distributed import get_task_stream

    from aftmesh.parallel import auto_chunksize

    domains = [box(i, 0, i + 1, 1 + 0.01 * i) for i in range(200)]
    workers = dask_client.scheduler_info()["workers"].values()
    chunk = auto_chunksize(len(domains), sum(w["nthreads"] for w in workers))
    assert chunk > 1
    with get_task_stream(dask_client) as stream:
        out = aftmesh.generate_many(domains, 0.5, client=dask_client)
    assert len(stream.data) == -(-len(domains) // chunk)
    for i in (0, 77, 199):
        assert_same(checked(out[i]), aftmesh.generate(domains[i], 0.5))


@pytest.mark.parametrize("kind", BACKENDS, ids=["serial", "threads", "dask"])
def test_more_domains_than_tasks_in_flight_all_come_back_in_order(kind, request, checked):
    # 2 workers keep at most 8 tasks in flight: 30 domains refill the window many times
    domains = [box(i, 0, i + 1, 1 + 0.1 * i) for i in range(30)]
    out = aftmesh.generate_many(
        domains, 0.5, chunksize=2 if kind == "dask" else None, **backend(kind, request)
    )
    for i, mesh in enumerate(out):
        assert checked(mesh).area() == pytest.approx(domains[i].area, rel=1e-12)


def test_imap_many_yields_every_index_once_from_a_generator(serial_meshes, checked):
    domains, _sizes = batch()
    lazy = (d for i, d in enumerate(domains) if i != BAD_INDEX)
    got = dict(aftmesh.imap_many(lazy, 0.1, workers=2))
    assert sorted(got) == list(range(len(domains) - 1))
    ref = aftmesh.generate(domains[0], 0.1)
    assert_same(checked(got[0]), ref)


class DuckFrame:
    """What generate_many reads of a GeoDataFrame: a geometry column and other columns
    (geopandas itself is not a test dependency)."""

    def __init__(self, geometry, **columns):
        self.geometry = geometry
        self._columns = columns
        self.columns = list(columns) + ["geometry"]

    def __getitem__(self, name):
        return self._columns[name]

    def __iter__(self):  # a DataFrame iterates over its column names
        return iter(self.columns)


def test_a_geodataframe_contributes_its_geometry_and_a_size_column(serial_meshes, checked):
    domains, sizes = batch()
    frame = DuckFrame(domains[:2], h=sizes[:2])
    out = aftmesh.generate_many(frame, "h", scheduler="serial")
    for mesh, ref in zip(out, serial_meshes[:2]):
        assert_same(checked(mesh), ref)


def test_sizes_not_matching_the_domains_are_refused_naming_both_lengths():
    domains, _ = batch()
    with pytest.raises(aftmesh.InvalidOptionError, match="size has 2 entries for 6 domains"):
        aftmesh.generate_many(domains, [0.1, 0.2])


@pytest.mark.parametrize(
    "options, message",
    [
        ({"scheduler": "mpi"}, "scheduler='mpi' is not a valid option"),
        ({"errors": "ignore"}, "errors='ignore' is not a valid option"),
        ({"workers": 0}, "workers must be a positive integer"),
        ({"scheduler": "dask"}, "no active dask.distributed Client"),
    ],
)
def test_bad_options_are_refused_by_name(options, message):
    with pytest.raises(aftmesh.InvalidOptionError, match=message):
        aftmesh.generate_many([box(0, 0, 1, 1)], 0.5, **options)


def test_threads_hand_over_results_in_batches_without_losing_or_hiding_any(checked):
    # more domains than one batch of results (parallel.RESULTS_PER_WAKE), one failing
    from aftmesh.parallel import RESULTS_PER_WAKE

    n = 2 * RESULTS_PER_WAKE + 5
    bad = RESULTS_PER_WAKE + 3
    domains = [box(i, 0, i + 1, 1) for i in range(n)]
    domains[bad] = BOWTIE
    out = aftmesh.generate_many(domains, 0.5, workers=2, errors="collect")
    assert [isinstance(m, MeshingFailure) for m in out] == [i == bad for i in range(n)]
    for i, mesh in enumerate(out):
        if i != bad:
            assert checked(mesh).area() == pytest.approx(1.0, rel=1e-12)
    with pytest.raises(aftmesh.InvalidDomainError, match=f"domain {bad}: ") as info:
        aftmesh.generate_many(domains, 0.5, workers=2)
    assert info.value.index == bad
