"""Size specifications -> the compiled size field.

A user's ``size`` is a number (the target edge length everywhere), a callable
``f(x, y) -> array`` evaluated on whole arrays at once (never one call per point: x
and y are 1-D arrays of equal length, the result one size per point or a scalar), or
``None`` (sizes taken from the lengths of the boundary's own edges and spread inward).

Whatever it is, it is combined with what the boundary asks for (an input edge shorter
than the size keeps its length as the size at its ends; with split_boundary=False, where
two edges meet at a wide angle, the geometric mean of theirs) and gradation-limited, so
that the size grows no faster than ``gradation`` per unit of length relative to itself
(h(x) <= h(y) + (gradation - 1) |x - y|) along the background's edges and around each of
its vertices (across a long background triangle next to much smaller sizes it can grow
faster: cython_ext/sizing.pxi says where and by how much).  The result is a constant, or
sizes at the vertices of a background Delaunay triangulation of the input vertices (plus
the points where a callable needed more samples), read by the kernel as
cython_ext/sizing.pxi says.  So the field costs what the input costs, never what its
bounding box spans: a long thin domain or a tiny edge does not make it bigger.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _kernel
from ._order import brio_order, round_keys
from ._typing import Point2, SizeFunction
from .errors import InvalidSizeError

if TYPE_CHECKING:
    import shapely

__all__ = ["SizeField", "make_size_field"]

DEFAULT_GRADATION = 1.3
# A user's size must span at least this many units in the last place of the domain's
# largest coordinate: new vertices are rounded to the nearest double, by up to half a
# unit per coordinate, so below this the mesh could not have the size asked for (and
# at a few units, the points that split an edge would coincide).
MIN_SIZE_ULPS = 64
# A constant size needs no background when no input edge is shorter than this fraction
# of it: the discretization rounds the number of pieces, so edges a little shorter
# than the size are met anyway.
CONSTANT_IF_EDGES_ABOVE = 0.8
# The background's corners lie this fraction of the domain's span beyond its bounding
# box, so points proposed just outside an edge still read a size from inside it.
BOX_PAD = 0.02
# A size callable is sampled at the midpoint of every background edge, and the
# midpoint becomes a background vertex where linear interpolation between the edge's
# ends misses the callable by more than this fraction ...
RESOLVE_TOLERANCE = 0.2
# ... unless the edge is already shorter than this many times the size there: the
# mesh cannot follow finer variation than its own edges anyway.
RESOLVE_SPAN = 1.0
# ... and an edge longer than this many times the size at its midpoint is split
# anyway: a callable is seen at least that closely everywhere (a feature of it
# narrower than that, far from the boundary, may go unseen).  A looser bound (32)
# cut a graded airfoil's evaluations by 3.5x, but a per-region size's jumps were then
# seen too coarsely: the demo's inclusion fell from 98.4 % to 96.8 % of triangles
# with a radius ratio above 0.9.
RESOLVE_COARSEST = 8
# Of the midpoints to insert in one round, those of edges of about the same length
# (lengths in one octave) closer than about this fraction of it become one point.  Next
# to a dense boundary the background's long edges come in fans, whose midpoints lie
# side by side: inserted all, they cost a graded airfoil 5,388 background points and
# 16,773 evaluations (the cap stopped it); thinned, 1,019 and 7,002, with the same
# mesh quality.  An edge left out is not passed: the next round samples it again.
RESOLVE_THIN = 0.5
# Sampling rounds (each one batched call of the callable) and evaluations in all: the
# bound on what a callable costs, whatever it does (a callable varying at every scale
# gets this much resolution and no more).
RESOLVE_ROUNDS = 24
RESOLVE_EVALUATIONS = 20_000
# How far (in its own lengths) a boundary edge's length holds as the size before it
# grows at the gradation rate: the first layer of triangles on a boundary is as large
# as its edges, and a short edge's size does not reach far.
BOUNDARY_REACH = 1.0


@dataclass(frozen=True, eq=False)
class SizeField:
    """Target edge length: ``constant`` when the background is empty, otherwise read
    from the background triangulation (``points``, ``triangles``, ``neighbors``) with
    the user's size ``user`` and the graded boundary size ``graded`` at its vertices
    (cython_ext/sizing.pxi).  Calling it evaluates the field the kernel uses.

    >>> f = make_size_field(0.5, ((0.0, 0.0), (1.0, 1.0)))
    >>> float(f(0.3, 0.7)), f.h_min
    (0.5, 0.5)
    """

    constant: float
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    user: np.ndarray = field(default_factory=lambda: np.zeros(0))
    graded: np.ndarray = field(default_factory=lambda: np.zeros(0))
    triangles: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=np.int32))
    neighbors: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=np.int32))
    rate: float = 0.0
    reach: float = 0.0

    @property
    def is_constant(self) -> bool:
        return len(self.triangles) == 0

    @property
    def h(self) -> np.ndarray:
        """The size at the background's vertices (the constant, if there are none)."""
        if self.is_constant:
            return np.array([self.constant])
        return np.minimum(self.user, self.graded)

    @cached_property
    def h_min(self) -> float:
        """The smallest size anywhere (interpolation and cones never go below the
        vertices' values)."""
        return float(self.h.min())

    def kernel_args(self) -> tuple:
        """The arguments of the kernel's ``set_size_field`` / ``size_field_eval``."""
        return (
            float(self.constant),
            self.points,
            self.user,
            self.graded,
            self.triangles,
            self.neighbors,
            float(self.rate),
            float(self.reach),
        )

    def __call__(self, x, y) -> np.ndarray:
        """The size at the points (x, y) (arrays of any one shape)."""
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        shape = np.broadcast(x, y).shape
        if self.is_constant:
            return np.full(shape, self.constant)
        xb, yb = (np.ascontiguousarray(np.broadcast_to(v, shape)).reshape(-1) for v in (x, y))
        return _kernel.size_field_eval(*self.kernel_args(), xb, yb).reshape(shape)


def _check_values(h: np.ndarray, X: np.ndarray, Y: np.ndarray, what: str) -> None:
    # two reductions decide the common case (a NaN fails both comparisons)
    if h.size == 0 or (h.min() > 0.0 and h.max() < np.inf):
        return
    bad = ~(np.isfinite(h) & (h > 0))
    if bad.any():
        k = np.flatnonzero(bad.ravel())[0]
        raise InvalidSizeError(
            f"{what} gave {h.ravel()[k]!r} at ({X.ravel()[k]:.6g}, {Y.ravel()[k]:.6g}): "
            "sizes must be finite and positive"
        )


def _resolution(bounds) -> float:
    """The spacing of doubles at the domain's largest coordinate (math.ulp of a
    finite magnitude below the largest double is np.spacing of it, without numpy's
    cost per call)."""
    (x0, y0), (x1, y1) = bounds
    return math.ulp(max(abs(float(x0)), abs(float(y0)), abs(float(x1)), abs(float(y1))))


def _check_resolution(h: np.ndarray, X, Y, bounds, what: str) -> None:
    """Refuse sizes finer than the coordinates can resolve (see MIN_SIZE_ULPS)."""
    spacing = _resolution(bounds)
    k = int(np.argmin(h))
    if h.ravel()[k] < MIN_SIZE_ULPS * spacing:
        magnitude = float(np.max(np.abs(np.asarray(bounds, dtype=np.float64))))
        where = "" if X is None else f" at ({X.ravel()[k]:.9g}, {Y.ravel()[k]:.9g})"
        raise InvalidSizeError(
            f"{what} {h.ravel()[k]:.6g}{where} is below what the coordinates can resolve: "
            f"near {magnitude:.6g}, doubles are {spacing:.3g} apart, and a size must span at "
            f"least {MIN_SIZE_ULPS} of those ({MIN_SIZE_ULPS * spacing:.3g}); use a larger "
            "size or move the domain nearer the origin"
        )


def _evaluate(size, X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """The user's size at the points (x, y), in one call: ``size(x, y)`` with x and y
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


def _parse_size(size) -> float | None:
    """The constant of a number size (checked), None for a callable or None."""
    if isinstance(size, (bool, np.bool_, str, bytes)):
        # float() would take True as 1 and "0.1" as 0.1: almost surely a mistake
        raise InvalidSizeError(f"size must be a number, a callable f(x, y) or None, got {size!r}")
    if size is None or callable(size):
        return None
    try:
        constant = float(size)
    except (TypeError, ValueError):
        raise InvalidSizeError(
            f"size must be a number, a callable f(x, y) or None, got {size!r}"
        ) from None
    if not (np.isfinite(constant) and constant > 0):
        raise InvalidSizeError(f"size must be finite and positive, got {size!r}")
    return constant


def _box_corners(bounds) -> np.ndarray:
    (xmin, ymin), (xmax, ymax) = bounds
    pad = BOX_PAD * max(xmax - xmin, ymax - ymin)
    x0, y0, x1, y1 = xmin - pad, ymin - pad, xmax + pad, ymax + pad
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=np.float64)


def _resolve_callable(size, tri, u: np.ndarray, bounds):
    """Sample the callable at the midpoints of the background's edges, round by round
    (one call each), and split the edges where interpolating between their ends
    misses it (RESOLVE_TOLERANCE) while longer than the size there (RESOLVE_SPAN), or
    where they are longer than RESOLVE_COARSEST sizes, inserting the first midpoint
    in each square cell of side RESOLVE_THIN 2**k among the edges of length in
    [2**k, 2**(k+1)), in spatial order (BRIO: fewer flips than the order of the edges,
    and the background it gives decides the ties between cocircular points), each
    walk started at its edge's first end.  An edge that passed once is not sampled
    again while it lasts.  The kernel runs the rounds (cython_ext/resolve.pxi),
    calling back here for the samples only.  Returns every background point and the
    size there."""

    def sample(mid: np.ndarray) -> np.ndarray:
        um = _evaluate(size, mid[:, 0], mid[:, 1])
        _check_resolution(um, mid[:, 0], mid[:, 1], bounds, "the size callable gave")
        return um

    return _kernel.resolve_rounds(
        tri, u, sample, round_keys, RESOLVE_EVALUATIONS, RESOLVE_ROUNDS,
        RESOLVE_TOLERANCE, RESOLVE_SPAN, RESOLVE_COARSEST, RESOLVE_THIN,
    )  # fmt: skip


def make_size_field(
    size: float | SizeFunction | None,
    bounds: tuple[Point2, Point2],
    boundary_points: np.ndarray | None = None,
    boundary_lengths: Any = None,  # (n,) floats or None (Any: None is tested by a flag)
    gradation: float = DEFAULT_GRADATION,
) -> SizeField:
    """Turn a size specification into a :class:`SizeField` over ``bounds``.

    The field is the smaller of the user's size and the sizes the boundary itself asks
    for: an input edge shorter than the user's size is kept, so the size at its ends
    is that edge's length, growing away from them at the gradation rate.  Without that,
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
    if isinstance(size, SizeField):
        # a field made before (a partitioned mesh's parts share the whole domain's):
        # it already holds the boundary's sizes and the gradation
        return size
    constant = _parse_size(size)
    if constant is not None and not constant >= MIN_SIZE_ULPS * _resolution(bounds):
        _check_resolution(np.array([constant]), None, None, bounds, "size")
    have_boundary = boundary_lengths is not None and len(boundary_lengths) > 0
    if constant is not None and (
        not have_boundary
        or np.asarray(boundary_lengths, dtype=np.float64).min()
        >= CONSTANT_IF_EDGES_ABOVE * constant
    ):
        # the boundary asks for nothing smaller: a constant needs no background
        return SizeField(constant)
    if size is None and not have_boundary:
        raise InvalidSizeError("size=None takes the size from the input edges, but there are none")
    corners = _box_corners(bounds)
    pts = corners
    lengths = np.full(4, np.inf)
    if have_boundary:
        pts = np.concatenate([np.asarray(boundary_points, dtype=np.float64), corners])
        # an edge shorter than the coordinates resolve (see MIN_SIZE_ULPS) stays as it
        # is, but asks for no smaller size around it: split points closer than that
        # would round onto each other
        floor = MIN_SIZE_ULPS * _resolution(bounds)
        edges = np.maximum(np.asarray(boundary_lengths, dtype=np.float64), floor)
        lengths = np.concatenate([edges, lengths])
    pts = np.ascontiguousarray(pts)
    if callable(size):
        return _callable_field(size, bounds, pts, lengths, gradation)
    u = np.full(len(pts), np.inf if constant is None else constant)
    return _numbers_field(constant, pts, u, lengths, gradation)


def _boundary_sizes(w: np.ndarray, lengths: np.ndarray, gradation) -> tuple[np.ndarray, float]:
    """The sizes to spread from the background's vertices, and the gradation they
    spread at.  The user's own size w joins the boundary's only when a gradation limit
    is asked for (gradation > 1): with gradation=1 it is honoured as given.  The
    boundary's sizes spread at the user's gradation, or the default one if the user
    asked for none (size=None with gradation=1 would otherwise leave the field
    infinite away from the boundary)."""
    spread = gradation if gradation > 1.0 else DEFAULT_GRADATION
    g = np.minimum(w, lengths) if gradation > 1.0 else lengths.copy()
    return g, spread


def _callable_field(size, bounds, pts: np.ndarray, lengths: np.ndarray, gradation):
    """make_size_field for a callable: sampled at the background's vertices and then
    where interpolation misses it (_resolve_callable), gradation-limited when asked,
    with the boundary's sizes spread as in _numbers_field."""
    u = _evaluate(size, pts[:, 0], pts[:, 1])
    _check_resolution(u, pts[:, 0], pts[:, 1], bounds, "the size callable gave")
    tri = _kernel.Triangulation(pts)
    tri.insert_points(brio_order(pts))
    pts, u = _resolve_callable(size, tri, u, bounds)
    lengths = np.concatenate([lengths, np.full(len(pts) - len(lengths), np.inf)])
    tv, nb = tri.finite_triangles()
    used = np.zeros(len(pts), dtype=bool)
    used[tv.ravel()] = True  # a point merged into an earlier one is in no triangle
    w = np.ascontiguousarray(u, dtype=np.float64)
    if gradation > 1.0:
        w = w.copy()
        _kernel.limit_gradation_mesh(pts, tv, w, float(gradation - 1.0))
    g, spread = _boundary_sizes(w, lengths, gradation)
    _kernel.limit_gradation_mesh(pts, tv, g, float(spread - 1.0))
    if not np.isfinite(g[used]).all():
        raise InvalidSizeError("could not derive a size from the boundary")
    g[~used] = np.inf  # never read: only the triangles' vertices are
    return SizeField(0.0, pts, w, g, tv, nb, spread - 1.0, BOUNDARY_REACH)


def _numbers_field(constant, pts: np.ndarray, u: np.ndarray, lengths: np.ndarray, gradation):
    """make_size_field without a callable: the background, the boundary's sizes and
    their gradation in one kernel call (the steps of _callable_field without the
    sampling; _boundary_sizes holds the gradation rules)."""
    g, spread = _boundary_sizes(u, lengths, gradation)
    tv, nb, finite = _kernel.background_field(pts, round_keys(len(pts)), g, spread - 1.0)
    if not finite:
        raise InvalidSizeError("could not derive a size from the boundary")
    return SizeField(constant or 0.0, pts, u, g, tv, nb, spread - 1.0, BOUNDARY_REACH)
