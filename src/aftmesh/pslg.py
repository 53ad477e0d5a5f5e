"""Validate a planar straight-line graph (PSLG) and build its constrained Delaunay
triangulation in the kernel.  Shared by :func:`aftmesh.cdt` and :func:`aftmesh.generate`.

Policies (stated once, here):

* Exactly coincident input vertices are merged; the merge is reported in
  ``Mesh.info['merged_vertices']``.
* A segment that runs exactly through another input vertex is split there.
* Two segments that cross at a point interior to both raise
  :class:`~aftmesh.errors.CrossingSegmentsError` naming both.
* With segments, every triangle reachable from outside the convex hull without
  crossing a segment is removed (so only regions enclosed by segments remain), then
  every region reachable from a hole point.  Without segments the convex hull is kept.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from . import _kernel
from ._order import round_keys
from ._states import TriangleState
from .errors import CrossingSegmentsError, InvalidDomainError, InvalidInputError

# The exact predicates are exact for coordinates that are 0 or of magnitude between
# these bounds (beyond, intermediate products could overflow or underflow; see
# cython_ext/predicates.pxi): other coordinates are refused with a message saying so.
MIN_COORDINATE, MAX_COORDINATE = _kernel.EXACT_COORDINATE_RANGE
# The bits of _kernel.coordinate_problems and _kernel.segment_problems.
COORDINATE_NOT_FINITE = 1
SEGMENT_OUT_OF_RANGE, SEGMENT_ZERO_LENGTH = 1, 2


@dataclass
class BuiltCDT:
    kernel: _kernel.Triangulation
    vertices: np.ndarray  # (n, 2) the validated input vertices
    segments: np.ndarray  # (m, 2) segments in input vertex numbering
    merged: np.ndarray  # (n,) input vertex -> kernel vertex it was merged into
    n_merged: int
    n_split: int = 0  # segments that ran exactly through another vertex


def as_points(value: npt.ArrayLike | None, name: str) -> np.ndarray:
    """An (n, 2) float64 array of finite coordinates, or an error naming the bad row."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be an (n, 2) array of numbers: {exc}") from None
    if arr.size == 0:
        return np.zeros((0, 2), dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise InvalidInputError(f"{name} must have shape (n, 2), got {arr.shape}")
    arr = np.ascontiguousarray(arr)
    # one compiled pass for the usual case; the row at fault is found only if needed
    problems = _kernel.coordinate_problems(arr, MIN_COORDINATE, MAX_COORDINATE)
    if problems & COORDINATE_NOT_FINITE:
        i = int(np.flatnonzero(~np.isfinite(arr).all(axis=1))[0])
        raise InvalidInputError(f"{name}[{i}] = {arr[i].tolist()} is not finite")
    if problems:
        check_range(arr, name)
    return arr


def check_range(arr: np.ndarray, name: str) -> None:
    """Refuse coordinates outside the exact predicates' range (see MAX_COORDINATE)."""
    arr = np.ascontiguousarray(arr, dtype=np.float64)
    if (
        not _kernel.coordinate_problems(arr, MIN_COORDINATE, MAX_COORDINATE)
        & ~COORDINATE_NOT_FINITE
    ):
        return
    mag = np.abs(arr)
    big = (mag > MAX_COORDINATE).any(axis=1)
    if big.any():
        i = int(np.flatnonzero(big)[0])
        raise InvalidInputError(
            f"{name}[{i}] = {arr[i].tolist()} is too large (|coordinate| > {MAX_COORDINATE:g}, "
            "beyond the range where the exact predicates are exact): rescale the domain"
        )
    tiny = ((mag < MIN_COORDINATE) & (mag > 0)).any(axis=1)
    if tiny.any():
        i = int(np.flatnonzero(tiny)[0])
        raise InvalidInputError(
            f"{name}[{i}] = {arr[i].tolist()} has a coordinate below {MIN_COORDINATE:g} in "
            "magnitude (but not 0), beneath the range where the exact predicates are exact: "
            "rescale the domain"
        )


def as_segments(value: npt.ArrayLike | None, n_vertices: int, vertices: np.ndarray) -> np.ndarray:
    if value is None:
        return np.zeros((0, 2), dtype=np.int32)
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"segments must be an (m, 2) array of indices: {exc}") from None
    if raw.size == 0:
        return np.zeros((0, 2), dtype=np.int32)
    if raw.ndim != 2 or raw.shape[1] != 2:
        raise InvalidInputError(f"segments must have shape (m, 2), got {raw.shape}")
    if not np.issubdtype(raw.dtype, np.integer):
        as_int = raw.astype(np.int64) if np.issubdtype(raw.dtype, np.number) else None
        if as_int is None or not np.array_equal(as_int, raw):
            raise InvalidInputError("segments must hold integer vertex indices")
        raw = as_int
    seg = raw.astype(np.int64)
    vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    # one compiled pass for the usual case; the segment at fault only if needed
    problems = _kernel.segment_problems(seg, vertices[:n_vertices])
    if problems & SEGMENT_OUT_OF_RANGE:
        bad = (seg < 0) | (seg >= n_vertices)
        i = int(np.flatnonzero(bad.any(axis=1))[0])
        raise InvalidInputError(
            f"segments[{i}] = {seg[i].tolist()} refers to a vertex outside 0..{n_vertices - 1}"
        )
    if problems & SEGMENT_ZERO_LENGTH:
        zero = (seg[:, 0] == seg[:, 1]) | (vertices[seg[:, 0]] == vertices[seg[:, 1]]).all(axis=1)
        i = int(np.flatnonzero(zero)[0])
        raise InvalidInputError(
            f"segments[{i}] = {seg[i].tolist()} has zero length "
            f"(both ends at {vertices[seg[i, 0]].tolist()})"
        )
    return seg.astype(np.int32)


# Mesh.regions holds int32 markers; Triangle's regional attributes may be any number,
# so build_cdt refuses a fractional or larger one rather than silently truncate it
MAX_REGION_MARKER = 2**31 - 1


def fractional_markers(markers: np.ndarray) -> np.ndarray:
    """Which region markers are not whole numbers (NaN included)."""
    return markers != np.rint(markers)


def markers_out_of_range(markers: np.ndarray) -> np.ndarray:
    """Which region markers an int32 does not hold."""
    return np.abs(markers) > MAX_REGION_MARKER


def build_cdt(
    vertices: npt.ArrayLike,
    segments: npt.ArrayLike | None = None,
    holes: npt.ArrayLike | None = None,
    regions: npt.ArrayLike | None = None,
    *,
    carve: bool | None = None,
    nt_hint: int = 0,
) -> BuiltCDT:
    """Validate a PSLG and return the kernel triangulation of its domain.

    ``regions`` is a sequence of (x, y, marker) rows; ``holes`` an (h, 2) array.
    ``carve`` (default: whether there are segments) removes what lies outside all
    closed rings of segments."""
    pts = as_points(vertices, "vertices")
    n = len(pts)
    if n < 3:
        raise InvalidDomainError(f"need at least 3 vertices, got {n}")
    seg = as_segments(segments, n, pts)
    hole_pts = as_points(holes if holes is not None else np.zeros((0, 2)), "holes")
    if regions is None:
        reg = np.zeros((0, 3))
    else:
        try:
            reg = np.asarray(regions, dtype=np.float64).reshape(-1, 3)
        except (TypeError, ValueError) as exc:
            raise InvalidInputError(f"regions must be rows of (x, y, marker): {exc}") from None
        if not np.isfinite(reg).all():
            i = int(np.flatnonzero(~np.isfinite(reg).all(axis=1))[0])
            raise InvalidInputError(f"regions[{i}] = {reg[i].tolist()} is not finite")
        frac = fractional_markers(reg[:, 2])
        if frac.any():
            i = int(np.flatnonzero(frac)[0])
            raise InvalidInputError(
                f"regions[{i}] has marker {float(reg[i, 2])!r}: region markers must be integers"
            )
        big = markers_out_of_range(reg[:, 2])
        if big.any():
            i = int(np.flatnonzero(big)[0])
            raise InvalidInputError(
                f"regions[{i}] has marker {float(reg[i, 2])!r}, out of the int32 range"
            )
    if carve is None:
        carve = len(seg) > 0
    kernel = _kernel.Triangulation(pts, nt_hint)
    try:
        # BRIO insertion, the segments (on the vertices the points merged into), and
        # the carve from the hull: one kernel call
        merged, n_merged, n_split = kernel.insert_pslg(round_keys(n), seg, carve)
    except _kernel.CollinearError:
        raise InvalidDomainError(
            f"all {n} vertices are collinear: there is no triangle to make"
        ) from None
    except _kernel.CrossingError as err:
        # the kernel knows exactly which input segment the blocking edge is a piece of
        i, j = err.index, err.blocker_segment
        a, b = seg[i]
        if j >= 0:
            c, d = seg[j]
            msg = (
                f"segments[{i}] = [{a}, {b}] ({pts[a].tolist()} -> {pts[b].tolist()}) "
                f"crosses segments[{j}] = [{c}, {d}] ({pts[c].tolist()} -> {pts[d].tolist()})"
            )
            raise CrossingSegmentsError(msg, (i, j)) from None
        raise CrossingSegmentsError(
            f"segments[{i}] = [{a}, {b}] crosses another segment", (i,)
        ) from None
    for name, rows in (("holes", hole_pts), ("regions", reg[:, :2])):
        for i, (x, y) in enumerate(rows):
            state = kernel.state_at(x, y)
            if state is None:
                raise InvalidDomainError(
                    f"{name}[{i}] = ({x:.6g}, {y:.6g}) lies on a segment, so it picks no "
                    "single region: put it strictly inside"
                )
            if state != TriangleState.UNMESHED:
                raise InvalidDomainError(
                    f"{name}[{i}] = ({x:.6g}, {y:.6g}) is not inside the domain"
                )
    if len(hole_pts):  # without holes, the carve above left nothing to do
        kernel.carve(hole_pts, False)
    if len(reg):
        kernel.assign_regions(
            np.ascontiguousarray(reg[:, :2]), np.ascontiguousarray(reg[:, 2].astype(np.int32))
        )
    return BuiltCDT(kernel, pts, seg, merged, n_merged, n_split)
