"""Size specifications -> the compiled size field (a background grid).

A user's ``size`` is a number (the target edge length everywhere), a callable
``f(x, y) -> array`` evaluated on whole arrays at once (never one call per point: x
and y are 1-D arrays of equal length, the result one size per point or a scalar), or
``None`` (sizes taken from the lengths of the boundary's own edges and spread inward).
Whatever it is, it becomes a regular grid of target lengths that the kernel
interpolates bilinearly, after a gradation limit has been applied so that the size
never grows faster than ``gradation`` per unit of length relative to itself
(h(x) <= h(y) + (gradation - 1) |x - y|).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ._kernel import limit_gradation_grid
from ._typing import Point2, SizeFunction
from .errors import InvalidSizeError

if TYPE_CHECKING:
    import shapely

__all__ = ["SizeField", "make_size_field"]

# The background grid has at most this many nodes along its longer side.
MAX_GRID = 512
DEFAULT_GRADATION = 1.3
# A user's size must span at least this many units in the last place of the domain's
# largest coordinate: new vertices are rounded to the nearest double, by up to half a
# unit per coordinate, so below this the mesh could not have the size asked for (and
# at a few units, the points that split an edge would coincide).
MIN_SIZE_ULPS = 64
# How far (in its own edge lengths) a boundary edge's length holds as the size before
# it grows at the gradation rate (see make_size_field).
BOUNDARY_REACH = 10.0
# A constant size needs no grid when no input edge is shorter than this fraction of
# it: the discretization rounds the number of pieces, so edges a little shorter than
# the size are met anyway.
CONSTANT_IF_EDGES_ABOVE = 0.8
# The grid reaches this fraction of the domain's span beyond its bounding box, so
# points proposed just outside an edge still read a size from inside the grid.
GRID_PAD = 0.02
# The coarsest grid spacing, as a fraction of the domain's span: finer features of a
# size callable than that are not seen by the first, coarse look.
COARSE_CELLS = 64
# The grid spacing is at most this fraction of the smallest size it must resolve
# (two nodes per size: bilinear interpolation then follows it closely).
NODES_PER_SIZE = 0.5


@dataclass(frozen=True)
class SizeField:
    """Target edge length on a regular grid: ``h[j, i]`` at ``(x0 + i dx, y0 + j dy)``."""

    x0: float
    y0: float
    dx: float
    dy: float
    h: np.ndarray

    @property
    def h_min(self) -> float:
        return float(self.h.min())

    def __call__(self, x, y) -> np.ndarray:
        """Bilinear interpolation, clamped outside the grid (as the kernel does it)."""
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        ny, nx = self.h.shape
        if nx == 1 and ny == 1:
            return np.full(np.broadcast(x, y).shape, self.h[0, 0])
        fx = np.clip((x - self.x0) / self.dx, 0, nx - 1) if nx > 1 else np.zeros_like(x)
        fy = np.clip((y - self.y0) / self.dy, 0, ny - 1) if ny > 1 else np.zeros_like(y)
        i = np.minimum(fx.astype(np.int64), max(nx - 2, 0))
        j = np.minimum(fy.astype(np.int64), max(ny - 2, 0))
        tx = fx - i
        ty = fy - j
        i1 = np.minimum(i + 1, nx - 1)
        j1 = np.minimum(j + 1, ny - 1)
        h = self.h
        return (1 - ty) * ((1 - tx) * h[j, i] + tx * h[j, i1]) + ty * (
            (1 - tx) * h[j1, i] + tx * h[j1, i1]
        )


def _check_values(h: np.ndarray, X: np.ndarray, Y: np.ndarray, what: str) -> None:
    bad = ~(np.isfinite(h) & (h > 0))
    if bad.any():
        k = np.flatnonzero(bad.ravel())[0]
        raise InvalidSizeError(
            f"{what} gave {h.ravel()[k]!r} at ({X.ravel()[k]:.6g}, {Y.ravel()[k]:.6g}): "
            "sizes must be finite and positive"
        )


def _check_resolution(h: np.ndarray, X, Y, bounds, what: str) -> None:
    """Refuse sizes finer than the coordinates can resolve (see MIN_SIZE_ULPS)."""
    magnitude = float(np.max(np.abs(np.asarray(bounds, dtype=np.float64))))
    spacing = float(np.spacing(magnitude))
    k = int(np.argmin(h))
    if h.ravel()[k] < MIN_SIZE_ULPS * spacing:
        where = "" if X is None else f" at ({X.ravel()[k]:.9g}, {Y.ravel()[k]:.9g})"
        raise InvalidSizeError(
            f"{what} {h.ravel()[k]:.6g}{where} is below what the coordinates can resolve: "
            f"near {magnitude:.6g}, doubles are {spacing:.3g} apart, and a size must span at "
            f"least {MIN_SIZE_ULPS} of those ({MIN_SIZE_ULPS * spacing:.3g}); use a larger "
            "size or move the domain nearer the origin"
        )


def _evaluate(size, X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """The user's size at the grid nodes, in one call: ``size(x, y)`` with x and y
    1-D arrays of equal length (the nodes row by row), returning that many sizes or
    one number.  1-D because that is what point-based tools take (``np.c_[x, y]``,
    KD-trees, interpolators, ``shapely.distance`` of points)."""
    x = np.ascontiguousarray(X, dtype=np.float64).reshape(-1)
    y = np.ascontiguousarray(Y, dtype=np.float64).reshape(-1)
    try:
        out = size(x, y)
    except Exception as exc:  # the user's function failed: say so, keep the cause
        raise InvalidSizeError(f"the size callable raised {type(exc).__name__}: {exc}") from exc
    try:
        values = np.asarray(out, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidSizeError(f"the size callable must return numbers: {exc}") from None
    if values.ndim == 0:
        h = np.full(X.shape, float(values))
    elif values.shape == x.shape:
        h = values.reshape(X.shape).copy()
    else:
        raise InvalidSizeError(
            f"the size callable returned an array of shape {values.shape}: it is called "
            f"with 1-D arrays x, y of length {len(x)} and must return an array of that "
            "length (one size per point) or a single number"
        )
    _check_values(h, X, Y, "the size callable")
    return h


def per_region_size(polygons: Sequence[shapely.Polygon], sizes: Iterable[float]) -> SizeFunction:
    """A size callable from one size per region: each region's own value inside it,
    the largest value outside all of them (the gradation limit then blends the values
    across interfaces, from the smaller side)."""
    import shapely

    values = []
    for k, v in enumerate(sizes):
        if isinstance(v, (bool, np.bool_, str, bytes)):
            raise InvalidSizeError(f"size[{k}] = {v!r} is not a number")
        try:
            v = float(v)
        except (TypeError, ValueError):
            raise InvalidSizeError(f"size[{k}] = {v!r} is not a number") from None
        if not (np.isfinite(v) and v > 0):
            raise InvalidSizeError(f"size[{k}] = {v!r}: sizes must be finite and positive")
        values.append(v)
    if len(values) != len(polygons):
        raise InvalidSizeError(
            f"got {len(values)} sizes for {len(polygons)} regions: give one size per region"
        )
    prepared = list(polygons)
    for p in prepared:
        shapely.prepare(p)  # speeds up the repeated point-in-polygon tests

    def size(x, y):
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        out = np.full(np.broadcast(x, y).shape, max(values))
        for poly, v in zip(prepared, values):
            inside = shapely.intersects_xy(poly, x, y)
            out[inside] = np.minimum(out[inside], v)
        return out

    return size


def limit_gradation(h: np.ndarray, dx: float, dy: float, gradation: float) -> np.ndarray:
    """Smallest field <= h with h(p) <= h(q) + (gradation - 1) * |p - q| along paths of
    grid nodes (the kernel's 8-neighbour sweeps)."""
    if gradation <= 1.0 or h.size <= 1:
        return h
    out = np.ascontiguousarray(h, dtype=np.float64).copy()
    limit_gradation_grid(out, float(dx), float(dy), float(gradation - 1.0))
    return out


def _nodes(bounds, spacing: float):
    """The grid's origin, spacings and node coordinates along x and along y."""
    (xmin, ymin), (xmax, ymax) = bounds
    span = max(xmax - xmin, ymax - ymin)
    spacing = max(spacing, span / (MAX_GRID - 1))
    nx = int(np.ceil((xmax - xmin) / spacing)) + 1
    ny = int(np.ceil((ymax - ymin) / spacing)) + 1
    nx = max(nx, 2)
    ny = max(ny, 2)
    dx = (xmax - xmin) / (nx - 1) if xmax > xmin else 1.0
    dy = (ymax - ymin) / (ny - 1) if ymax > ymin else 1.0
    xs = xmin + dx * np.arange(nx)
    ys = ymin + dy * np.arange(ny)
    return xmin, ymin, dx, dy, xs, ys


def _grid(bounds, spacing: float):
    """As :func:`_nodes`, with the nodes' coordinates as two full 2-D arrays."""
    x0, y0, dx, dy, xs, ys = _nodes(bounds, spacing)
    X, Y = np.meshgrid(xs, ys)
    return x0, y0, dx, dy, X, Y


def make_size_field(
    size: float | SizeFunction | None,
    bounds: tuple[Point2, Point2],
    boundary_points: np.ndarray | None = None,
    boundary_lengths: Any = None,  # (n,) floats or None (Any: None is tested by a flag)
    gradation: float = DEFAULT_GRADATION,
) -> SizeField:
    """Turn a size specification into a :class:`SizeField` over ``bounds``.

    The field is the smaller of the user's size and the sizes the boundary itself asks
    for: an input edge shorter than the user's size is kept, so the size near its ends
    is that edge's length, growing away from it at the gradation rate.  Without that,
    a triangle built on a short edge would have to be either a needle or much smaller
    than its neighbours.

    Parameters
    ----------
    size : float, callable or None
        None: the boundary's edge lengths alone.
    bounds : ((xmin, ymin), (xmax, ymax))
    boundary_points, boundary_lengths : arrays
        The input vertices and the length of the shortest input edge at each.
    gradation : float >= 1
        Largest growth of the size per unit of length, as a factor: h may grow by
        (gradation - 1) times the distance; 1 means no limit.
    """
    if gradation is None or not np.isfinite(gradation) or gradation < 1.0:
        raise InvalidSizeError(f"gradation must be a finite number >= 1, got {gradation!r}")
    constant = None
    if isinstance(size, (bool, np.bool_, str, bytes)):
        # float() would take True as 1 and "0.1" as 0.1: almost surely a mistake
        raise InvalidSizeError(f"size must be a number, a callable f(x, y) or None, got {size!r}")
    if size is not None and not callable(size):
        try:
            constant = float(size)
        except (TypeError, ValueError):
            raise InvalidSizeError(
                f"size must be a number, a callable f(x, y) or None, got {size!r}"
            ) from None
        if not (np.isfinite(constant) and constant > 0):
            raise InvalidSizeError(f"size must be finite and positive, got {size!r}")
        _check_resolution(np.array([constant]), None, None, bounds, "size")
    have_boundary = boundary_lengths is not None and len(boundary_lengths) > 0
    if constant is not None and (
        not have_boundary or float(np.min(boundary_lengths)) >= CONSTANT_IF_EDGES_ABOVE * constant
    ):
        # the boundary asks for nothing smaller: a constant needs no grid
        return SizeField(0.0, 0.0, 1.0, 1.0, np.array([[constant]]))
    if size is None and not have_boundary:
        raise InvalidSizeError("size=None takes the size from the input edges, but there are none")
    (xmin, ymin), (xmax, ymax) = bounds
    span = max(xmax - xmin, ymax - ymin)
    pad = GRID_PAD * span
    bounds = ((xmin - pad, ymin - pad), (xmax + pad, ymax + pad))
    spacing = span / COARSE_CELLS
    if have_boundary:
        spacing = min(spacing, NODES_PER_SIZE * float(np.min(boundary_lengths)))
    if callable(size):
        # a coarse look first, to pick a grid spacing fine enough for the smallest size
        x0, y0, dx, dy, X, Y = _grid(bounds, span / COARSE_CELLS)
        h0 = _evaluate(size, X, Y)
        _check_resolution(h0, X, Y, bounds, "the size callable gave")
        spacing = min(spacing, NODES_PER_SIZE * float(h0.min()))
    # the full 2-D node coordinates only for a callable: elsewhere node (j, i) is
    # read as (xs[i], ys[j]), the same numbers without two grid-sized arrays
    x0, y0, dx, dy, xs, ys = _nodes(bounds, spacing)
    shape = (len(ys), len(xs))
    if callable(size):
        X, Y = np.meshgrid(xs, ys)
        h = _evaluate(size, X, Y)
        _check_resolution(h, X, Y, bounds, "the size callable gave")
    else:
        h = np.full(shape, np.inf if constant is None else constant)
    # the growth rate used to spread the boundary's sizes: the user's gradation, or
    # the default one if the user asked for none (size=None with gradation=1 would
    # otherwise leave the field infinite away from the boundary)
    spread = gradation if gradation > 1.0 else DEFAULT_GRADATION
    if have_boundary:
        pts = np.asarray(boundary_points, dtype=np.float64)
        lengths = np.asarray(boundary_lengths, dtype=np.float64)
        # each boundary vertex asks for its edge length at the four grid nodes around
        # it, as is out to BOUNDARY_REACH edge lengths away and growing at the
        # gradation rate beyond (not the bare length at any distance: a cell can be
        # far larger than a tiny edge, and bilinear interpolation would spread that
        # tiny size over the whole cell; nor growing from the vertex itself: the
        # field would then be larger than the boundary's edges right next to them,
        # and the first layer of triangles on a graded boundary would be stretched)
        rate = spread - 1.0
        i = np.clip(np.floor((pts[:, 0] - x0) / dx).astype(np.int64), 0, shape[1] - 2)
        j = np.clip(np.floor((pts[:, 1] - y0) / dy).astype(np.int64), 0, shape[0] - 2)
        for di in (0, 1):
            for dj in (0, 1):
                dist = np.hypot(xs[i + di] - pts[:, 0], ys[j + dj] - pts[:, 1])
                np.minimum.at(
                    h,
                    (j + dj, i + di),
                    lengths + rate * np.maximum(0.0, dist - BOUNDARY_REACH * lengths),
                )
    limit = spread if not np.isfinite(h).all() else gradation
    if limit > 1.0 and h.size > 1:
        # as limit_gradation, in place: h is this function's own C-ordered array
        limit_gradation_grid(h, float(dx), float(dy), float(limit - 1.0))
    if not np.isfinite(h).all():
        raise InvalidSizeError("could not derive a size from the boundary")
    return SizeField(float(x0), float(y0), float(dx), float(dy), np.ascontiguousarray(h))
