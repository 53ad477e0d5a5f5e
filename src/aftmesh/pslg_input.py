"""Input adapters for Triangle-style PSLGs: a dict (``vertices``, ``segments``,
``holes``, ``regions``, ``segment_markers``) or a ``.poly`` file -> :class:`Domain`.

Input edges are numbered by their index in ``segments`` (``Mesh.segment_sources``).
"""

from __future__ import annotations

import numpy as np

from ._typing import PathArg
from .domain_record import Domain, PositionalNames
from .errors import InvalidInputError
from .noding import merge_close_segments, refuse_crossings, split_at_vertices
from .pslg import as_points, as_segments

__all__ = ["from_dict", "from_poly_file"]


def _dict_regions(regions):
    if regions is None:
        return None
    try:
        reg = np.asarray(regions, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"regions must be rows of (x, y, marker[, max_area]): {exc}"
        ) from None
    if reg.size == 0:
        return None
    if reg.ndim != 2 or reg.shape[1] < 3:
        raise InvalidInputError(f"regions must have shape (r, 3) or (r, 4), got {reg.shape}")
    return reg[:, :3]


def _dict_markers(markers, n_segments: int):
    if markers is None:
        return None
    try:
        markers = np.asarray(markers).reshape(-1)
    except (ValueError, TypeError) as exc:
        raise InvalidInputError(f"segment_markers must be a list of integers: {exc}") from None
    if len(markers) != n_segments:
        raise InvalidInputError(
            f"segment_markers has {len(markers)} entries for {n_segments} segments"
        )
    if not np.issubdtype(markers.dtype, np.integer):
        raise InvalidInputError("segment_markers must be integers")
    big = np.abs(markers.astype(np.int64)) > 2**31 - 1
    if big.any():
        i = int(np.flatnonzero(big)[0])
        raise InvalidInputError(
            f"segment_markers[{i}] = {int(markers[i])} is out of the int32 range"
        )
    return markers.astype(np.int32)


def from_dict(d: dict, presplit: bool = True, tolerance: float = 0.0) -> Domain:
    """A Triangle-style dict (``vertices``, ``segments``, ``holes``, ``regions``,
    ``segment_markers``): crossings refused, as :func:`aftmesh.cdt` does."""
    if "vertices" not in d:
        raise InvalidInputError("a domain dict needs 'vertices' (and usually 'segments')")
    pts = as_points(d["vertices"], "vertices")
    seg = as_segments(d.get("segments"), len(pts), pts)
    holes = as_points(d.get("holes", np.zeros((0, 2))), "holes")
    reg = _dict_regions(d.get("regions"))
    markers = _dict_markers(d.get("segment_markers"), len(seg))
    names = PositionalNames("segments", len(seg))
    mids = 0.5 * (pts[seg[:, 0]] + pts[seg[:, 1]])
    edges = np.arange(len(seg), dtype=np.int32)
    note: list[str] = []
    report = {"merged": 0, "snapped": 0}
    if tolerance > 0:
        pts, seg, edges, report["merged"] = merge_close_segments(pts, seg, edges, note, tolerance)
    refuse_crossings(pts, seg)
    # a segment running exactly through another vertex is split there now, before the
    # size splits it into pieces whose rounded ends would miss that vertex (kept whole,
    # the CDT splits it there exactly, at no cost here)
    if presplit or tolerance > 0:
        seg, edges = split_at_vertices(pts, seg, edges, note, tolerance, None, report)
    return Domain(
        pts,
        np.asarray(seg, dtype=np.int32),
        np.asarray(edges, dtype=np.int32),
        np.arange(len(names), dtype=np.int32),
        names,
        holes=holes,
        region_points=reg,
        source_markers=markers,
        cleanup=note,
        edge_midpoints=mids,
        report={"tolerance": report} if tolerance > 0 else {},
    )


def from_poly_file(path: PathArg, presplit: bool = True, tolerance: float = 0.0) -> Domain:
    """A Triangle ``.poly`` file: read into a dict, then as :func:`from_dict`."""
    from .io import read_poly

    try:
        d = read_poly(path)
    except OSError as exc:
        # a wrong path is the caller's input error like any other
        raise InvalidInputError(f"cannot read the domain file {str(path)!r}: {exc}") from None
    return from_dict(d, presplit, tolerance)
