"""``aftmesh.generate(domain, size, partitions=k)``: one domain meshed in k parts at once.

1. The boundary is discretized by the size field as a serial run would (a greedy run
   gives it, with the graded size field).
2. The bounding box is bisected recursively by straight lines across the longer side
   of each box, placed so that each side expects its share of triangles (the integral
   of 1/h^2 over a coarse sampling of the domain).
3. Each cut is discretized once by the size field; where it crosses a boundary piece,
   it ends on that piece's nearer vertex (the input edges stay exactly as they were).
4. The faces of boundary + cuts are found on their coarse CDT and given to the part
   whose box holds most of their area; each part is meshed with ``split_boundary=False``
   on threads, or as a Dask task.
5. The parts are stitched by vertex identity and Lawson flips from the cut edges
   restore the CDT property (see :mod:`aftmesh.stitch`).

If the cuts cannot be laid without crossing the boundary's pieces (a boundary
wiggling at the scale of the size right where a cut meets it), the domain is meshed
serially and ``info['partition_fallback']`` says why.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, overload

import numpy as np

from ._typing import DomainArg, PathArg, SizeArg
from .cuts import coarse_cdt, cut_pslg, discretized_boundary, part_inputs
from .errors import CrossingSegmentsError, InvalidOptionError
from .mesh import Mesh
from .stitch import lawson_flips, stitch_parts

if TYPE_CHECKING:
    from distributed import Client

    # a box (xmin, ymin, xmax, ymax)
    Box = tuple[float, float, float, float]

__all__ = ["generate_partitioned"]


def _mesh_part(part: dict, field, options: dict) -> Mesh:
    from .generate import generate

    return generate(part, field, split_boundary=False, **options)


def _mesh_part_fields(part: dict, field, options: dict) -> dict:
    """_mesh_part as a Dask task: the Mesh's fields as a dict, rebuilt by
    Mesh._adopt in the driver.  A dict of arrays travels by Dask's own array
    serializer; a Mesh falls back to pickle, which moved a 1e6-triangle mesh from a
    LocalCluster worker in 0.17-0.29 s against 0.09-0.13 s for its fields."""
    mesh = _mesh_part(part, field, options)
    return {f.name: getattr(mesh, f.name) for f in dataclasses.fields(mesh)}


def _run_parts(parts, field, options, client, workers):
    if client is not None:
        from distributed import as_completed

        # the size field goes to each worker once, not with every part
        field = client.scatter(field, broadcast=True)
        futures = client.map(_mesh_part_fields, parts, field=field, options=options, pure=False)
        # each part's mesh is fetched as soon as it is made, while the others are
        # still meshing (one gather of all waits for the last part before it moves
        # any part's arrays)
        slot = {future.key: i for i, future in enumerate(futures)}
        meshes: list = [None] * len(futures)
        for future in as_completed(futures, loop=client.loop):
            meshes[slot[future.key]] = Mesh._adopt(**future.result())
        return meshes
    workers = workers or min(len(parts), os.cpu_count() or 1)
    with cf.ThreadPoolExecutor(max_workers=workers, thread_name_prefix="aftmesh-part") as pool:
        return list(pool.map(lambda part: _mesh_part(part, field, options), parts))


def _check(partitions, options) -> int:
    if (
        isinstance(partitions, bool)
        or not isinstance(partitions, (int, np.integer))
        or partitions < 1
    ):
        raise InvalidOptionError(f"partitions must be a positive integer, got {partitions!r}")
    if partitions > 1:
        for name in ("max_triangles", "strategy", "boundary_tags"):
            if options.get(name) is not None:
                raise InvalidOptionError(f"{name} cannot be combined with partitions > 1")
        if options.get("greedy"):
            raise InvalidOptionError(
                "greedy=True adds no point, but partitions > 1 adds the cut vertices"
            )
    return int(partitions)


@overload
def generate_partitioned(
    domain: DomainArg,
    size: SizeArg = None,
    *,
    partitions: int,
    client: Client | None = None,
    workers: int | None = None,
    out: None = None,
    options: dict | None = None,
) -> Mesh: ...


@overload
def generate_partitioned(
    domain: DomainArg,
    size: SizeArg = None,
    *,
    partitions: int,
    client: Client | None = None,
    workers: int | None = None,
    out: PathArg,
    options: dict | None = None,
) -> Path: ...


def generate_partitioned(
    domain: DomainArg,
    size: SizeArg = None,
    *,
    partitions: int,
    client: Client | None = None,
    workers: int | None = None,
    out: PathArg | None = None,
    options: dict | None = None,
) -> Mesh | Path:
    """``aftmesh.generate(domain, size, partitions=k, client=..., out=...)``: see the
    module documentation.  ``options`` are generate's other keyword options.  With
    ``out`` (a directory) the parts are written there by the workers that mesh them
    (see :mod:`aftmesh.partition_io`) and the path of the ``.pvtu`` is returned."""
    from .generate import generate

    options = {k: v for k, v in (options or {}).items() if v is not None}
    k = _check(partitions, options)
    if k == 1 and client is None and out is None:
        return generate(domain, size, **options)
    t0 = time.perf_counter()
    b = discretized_boundary(domain, size, options)
    pts, seg, leaves, locate = cut_pslg(b, k)
    try:
        C = coarse_cdt(pts, seg)
        reason = (
            None
            if len(C.segments) == len(seg) and len(C.points) == len(pts)
            else "a cut runs through a vertex of the boundary"
        )
    except CrossingSegmentsError:
        reason = "a cut crosses the boundary's pieces"
    if reason is not None and out is None:
        mesh = generate(domain, size, **options)
        mesh.info["partition_fallback"] = reason
        return mesh
    if reason is not None:
        raise InvalidOptionError(f"out= cannot write this domain in parts: {reason}")
    parts, ids = part_inputs(C, leaves, locate)
    t1 = time.perf_counter()
    part_options = {
        key: v
        for key, v in options.items()
        if key not in ("split_boundary", "progress", "greedy", "repair", "tolerance")
    }
    if out is not None:
        from .partition_io import part_meta, write_parts

        metas = part_meta(C, ids, b.points[b.segments], b.markers)
        return write_parts(out, parts, metas, b.field, part_options, _mesh_part, client, workers)
    meshes = _run_parts(parts, b.field, part_options, client, workers)
    t2 = time.perf_counter()
    xy = b.points[b.segments]
    P, T, N, R, segments, markers, cut, cut_vertices, constrained = stitch_parts(
        meshes, xy, b.markers
    )
    flips = lawson_flips(P, T, N, constrained, cut)
    info = {
        "partitions": len(meshes),
        "part_triangles": [m.n_triangles for m in meshes],
        "cut_edges": len(cut),
        "cut_vertices": cut_vertices,
        "cut_flips": flips,
        "size_field": b.field,
        "timing": {
            "plan": t1 - t0,
            "parts": t2 - t1,
            "stitch": time.perf_counter() - t2,
            "total": time.perf_counter() - t0,
        },
    }
    return Mesh._adopt(
        points=P,
        triangles=T,
        neighbors=N,
        segments=segments,
        regions=R,
        segment_markers=markers,
        info=info,
    )
