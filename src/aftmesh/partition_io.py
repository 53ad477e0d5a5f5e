"""``generate(..., partitions=k, out=dir)``: each part written by the worker that made it.

The vertices of the boundary and of the cuts (the coarse PSLG the parts were cut from)
keep their coarse numbers as global ids, known before any part is meshed; the
vertices a part adds are numbered after them, in part order, once every part has
reported how many it added.  With a Dask client the part meshes stay on the workers
from meshing to writing: only the part inputs (the boundary of each part), a count
and a file summary move.  Without one, the parts are meshed on threads here.

The Lawson pass across the cuts (:func:`aftmesh.stitch.lawson_flips`) needs both sides
of a cut in one place, so it is not run: each part is the CDT of its own vertices and
segments, and ``info['cut_flips']`` of an in-memory run of the same domain says whether
a flip would have been needed (none in the test domains).
"""

from __future__ import annotations

import concurrent.futures as cf
import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ._typing import PathArg
from .pvtu import write_index, write_part
from .stitch import _void

if TYPE_CHECKING:
    from .mesh import Mesh

__all__ = ["write_parts"]


def _global_ids(mesh, part: dict, meta: dict, offset: int) -> np.ndarray:
    """Global id of each point of a part's mesh: the coarse id of its input
    vertices (found by exact coordinates), offset + a count for the others."""
    keys = _void(part["vertices"])
    order = np.argsort(keys)
    gid = np.full(mesh.n_points, -1, dtype=np.int64)
    ends = np.unique(mesh.segments)
    candidates = ends if meta["lone"] == 0 else np.arange(mesh.n_points)
    ck = _void(mesh.points[candidates])
    pos = np.minimum(np.searchsorted(keys[order], ck), len(keys) - 1)
    hit = keys[order][pos] == ck
    gid[candidates[hit]] = meta["ids"][order[pos[hit]]]
    new = gid < 0
    gid[new] = offset + np.arange(int(new.sum()))
    return gid


def _count_new(mesh, part: dict) -> int:
    return mesh.n_points - len(part["vertices"])


def _write(mesh, part: dict, meta: dict, offset: int, path: str) -> tuple:
    gid = _global_ids(mesh, part, meta, offset)
    seg = gid[mesh.segments]
    key = np.minimum(seg[:, 0], seg[:, 1]) * meta["n"] + np.maximum(seg[:, 0], seg[:, 1])
    pieces, markers = meta["pieces"], meta["markers"]
    pos = np.minimum(np.searchsorted(pieces, key), max(len(pieces) - 1, 0))
    keep = pieces[pos] == key if len(pieces) else np.zeros(len(key), dtype=bool)
    write_part(
        path,
        mesh.points,
        gid,
        mesh.triangles,
        mesh.regions,
        mesh.segments[keep],
        markers[pos[keep]],
    )
    return mesh.n_points, mesh.n_triangles


def part_meta(C: Mesh, used: list, input_xy: np.ndarray, input_markers: np.ndarray) -> list[dict]:
    """Per part: the global (coarse) ids of its vertices and the keys of the input
    pieces (not the cut pieces) with their markers."""
    n = len(C.points)
    keys = _void(C.points)
    order = np.argsort(keys)
    ends = order[np.searchsorted(keys[order], _void(input_xy.reshape(-1, 2)))].reshape(-1, 2)
    key = np.minimum(ends[:, 0], ends[:, 1]).astype(np.int64) * n + np.maximum(
        ends[:, 0], ends[:, 1]
    )
    srt = np.argsort(key)
    on_seg = np.zeros(n, dtype=bool)
    on_seg[C.segments.ravel()] = True
    return [
        {
            "ids": u.astype(np.int64),
            "n": n,
            "pieces": key[srt],
            "markers": np.asarray(input_markers)[srt],
            "lone": int((~on_seg[u]).sum()),
        }
        for u in used
    ]


def write_parts(
    out: PathArg,
    parts: list[dict],
    metas: list[dict],
    field: Callable[..., Any],  # the graded size field f(x, y)
    options: dict,
    mesh_part: Callable[..., Mesh],
    client: Any,  # a distributed.Client or None (Any: its branch reuses `meshes`)
    workers: int | None,
) -> Path:
    """Mesh and write every part; return the ``.pvtu`` path."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    names = [f"part{p:04d}.vtu" for p in range(len(parts))]
    paths = [str(out / name) for name in names]
    n = metas[0]["n"] if metas else 0
    if client is not None:
        field = client.scatter(field, broadcast=True)  # once per worker
        meshes = client.map(mesh_part, parts, field=field, options=options, pure=False)
        counts = client.gather(client.map(_count_new, meshes, parts, pure=False))
        offsets = (n + np.r_[0, np.cumsum(counts)[:-1]]).tolist()
        client.gather(client.map(_write, meshes, parts, metas, offsets, paths, pure=False))
    else:
        workers = workers or min(len(parts), os.cpu_count() or 1)
        with cf.ThreadPoolExecutor(max_workers=workers) as pool:
            meshes = list(pool.map(lambda part: mesh_part(part, field, options), parts))
            counts = [_count_new(m, part) for m, part in zip(meshes, parts)]
            offsets = (n + np.r_[0, np.cumsum(counts)[:-1]]).tolist()
            list(pool.map(_write, meshes, parts, metas, offsets, paths))
    index = out / "mesh.pvtu"
    write_index(index, names)
    return index
