"""``aftmesh.generate``: a quality triangle mesh of a domain by Basic_aft."""
from __future__ import annotations

import sys
import time

import numpy as np
import shapely

from .aft import Strategy, basic_aft
from .boundary import discretize
from .cdt import segment_markers
from .domain import classify_pieces, node_crossings, snap_tolerance, to_domain
from .errors import (CrossingSegmentsError, InvalidDomainError, InvalidOptionError,
                     InvalidSizeError)
from .mesh import Mesh
from .pslg import build_cdt
from .sizing import DEFAULT_GRADATION, make_size_field, per_region_size

__all__ = ["generate"]

_ORDERS = {"shortest": 0, "longest": 1, "oldest": 2}
MAX_SMOOTH = 1000           # smoothing rounds; it stops earlier once nothing moves
# Default bound of the minimum-angle pass (degrees): Delaunay refinement is proven to
# terminate up to about 26.5 degrees and does so in practice up to about 33.8; 28 leaves
# a margin below that and is what Basic_aft's meshes nearly meet already (few points).
DEFAULT_MIN_ANGLE = 28.0
MAX_MIN_ANGLE = 34.0
# Kernel indices are int32: refuse a request for more triangles than that can number
MAX_TRIANGLES = 2 ** 30


class _ProgressBar:
    """A one-line bar on standard error, redrawn only when the percentage changes."""

    def __init__(self, stream):
        self.stream = stream
        self.last = -1

    def __call__(self, fraction: float) -> None:
        pct = int(100 * min(max(fraction, 0.0), 1.0))
        if pct != self.last:
            self.last = pct
            filled = pct * 30 // 100
            self.stream.write(f"\raftmesh [{'#' * filled}{'.' * (30 - filled)}] {pct:3d}%")
            self.stream.flush()

    def close(self) -> None:
        if self.last >= 0:
            self.stream.write("\r" + " " * 48 + "\r")
            self.stream.flush()


def _progress_callback(progress, expected_triangles: int):
    if callable(progress):
        return progress
    if progress is None:
        progress = sys.stderr.isatty() and expected_triangles > 200_000
    return _ProgressBar(sys.stderr) if progress else None


def _expected_triangles(field, area: float, gradation: float) -> float:
    """About how many triangles the size field asks for on `area` (an equilateral
    triangle of side h has area 0.43 h^2).  On a grid, a node's cell is counted at most
    as a graded disk around a tiny size would be (the count around a point where h
    grows linearly from h0 is only logarithmic in 1/h0), so one tiny feature does not
    make the estimate explode."""
    with np.errstate(over="ignore", under="ignore", divide="ignore", invalid="ignore"):
        if field.h.size == 1:
            return float(np.float64(area) / (0.43 * np.float64(field.h_min)) / field.h_min)
        h = field.h
        rate = max(gradation - 1.0, 0.05)
        cell = field.dx * field.dy
        dense = cell / (0.43 * h) / h
        graded = (2 * np.pi / (0.43 * rate * rate)) * (
            1.0 + np.log1p(rate * max(field.dx, field.dy) / h))
        grid_area = cell * h.size
        return float(np.minimum(dense, graded).sum() * min(1.0, area / grid_area) * 1.2)


def _name_sources(err: CrossingSegmentsError, dom, verts, segs, src) -> CrossingSegmentsError:
    """The same error naming the user's segments / rings, not the pieces the
    discretization made of them."""
    names = [dom.source_names[src[k]] for k in err.segments if 0 <= k < len(src)]
    where = [verts[segs[k]].tolist() for k in err.segments if 0 <= k < len(src)]
    detail = " and ".join(f"{n} (near {w[0]} -> {w[1]})" for n, w in zip(names, where))
    return CrossingSegmentsError(f"these input edges cross: {detail}",
                                 tuple(int(src[k]) for k in err.segments))


def _real(name, value, error=InvalidOptionError) -> float:
    """A finite real number from an option value, or an error naming the option."""
    if isinstance(value, (bool, np.bool_)) or isinstance(value, (str, bytes)):
        raise error(f"{name} must be a number, got {value!r}")
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise error(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(out):
        raise error(f"{name} must be finite, got {value!r}")
    return out


def _min_angle(value) -> float:
    """The bound of the minimum-angle pass in degrees, 0 for none."""
    if value is None:
        return 0.0
    out = _real("min_angle", value)
    if out != 0 and not 0 < out <= MAX_MIN_ANGLE:
        raise InvalidOptionError(
            f"min_angle must be in (0, {MAX_MIN_ANGLE:g}] degrees (or 0 / None: no pass), "
            f"got {value!r}: Delaunay refinement is known to terminate only up to about "
            "33.8 degrees")
    return out


def _check_options(order, max_triangles, min_area, close_factor, smooth, strategy, flags):
    for name, value in flags.items():
        if not isinstance(value, (bool, np.bool_)):
            raise InvalidOptionError(f"{name} must be True or False, got {value!r}")
    if not isinstance(order, str) or order not in _ORDERS:
        raise InvalidOptionError(
            f"order={order!r} is not a valid option, must be one of {sorted(_ORDERS)}")
    if max_triangles is not None:
        if isinstance(max_triangles, bool) or not isinstance(max_triangles, (int, np.integer)):
            raise InvalidOptionError(f"max_triangles must be an integer, got {max_triangles!r}")
        if max_triangles < 1:
            raise InvalidOptionError(f"max_triangles must be positive, got {max_triangles}")
    if min_area is not None and _real("min_area", min_area) < 0:
        raise InvalidOptionError(f"min_area must be >= 0, got {min_area!r}")
    if not 0 <= _real("close_factor", close_factor) < 2:
        raise InvalidOptionError(f"close_factor must be in [0, 2), got {close_factor!r}")
    if isinstance(smooth, (bool, np.bool_)) or not isinstance(smooth, (int, np.integer)) \
            or not 0 <= smooth <= MAX_SMOOTH:
        raise InvalidOptionError(
            f"smooth must be a number of rounds from 0 to {MAX_SMOOTH}, got {smooth!r}")
    if strategy is not None and not isinstance(strategy, Strategy):
        raise InvalidOptionError(
            f"strategy must be an aftmesh.aft.Strategy (or a subclass), got {strategy!r}")


def generate(domain, size=None, *, max_triangles: int | None = None,
             min_area: float | None = None, order: str = "shortest", greedy: bool = False,
             swaps: bool = True, split_boundary: bool = True,
             gradation: float = DEFAULT_GRADATION, close_factor: float = 0.5,
             smooth: int = 3, strategy: Strategy | None = None, progress=None,
             min_angle: float | None = DEFAULT_MIN_ANGLE) -> Mesh:
    """Mesh a 2D domain with triangles by the advancing-front technique.

    Parameters
    ----------
    domain
        A shapely ``Polygon`` / ``MultiPolygon`` / ``GeometryCollection`` (lines and
        points inside the polygons become internal constraints), a sequence of
        polygons with disjoint interiors (one region each), an (n, 2) coordinate array
        (one ring), a Triangle-style dict (``vertices``, ``segments``, ``holes``,
        ``regions``), or the path of a ``.poly`` file.
    size : float, callable, sequence or None
        Target edge length: a number, ``f(x, y) -> array`` (called on whole arrays), one
        number per region (with a sequence of polygons as the domain), or None to take
        it from the lengths of the input edges.  A size must span at least 64 units in
        the last place of the largest coordinate (about 1e-14 of it); a finer one
        raises InvalidSizeError.
    max_triangles : int, optional
        N_max: the mesh never has more triangles (formula (4) of the paper).
    min_area : float, optional
        A_min: Basic_aft adds no vertex whose triangle would be smaller (formula (5);
        the minimum-angle pass is bounded by its own caps instead).  By default
        1 % of the area of an equilateral triangle of the smallest size.
    order : {'shortest', 'longest', 'oldest'}
        Get_next_edge: shortest front edge first (default), longest first, or oldest
        first (layer by layer).
    greedy : bool
        New_is_preferred always false: no point is added and the result is a
        triangulation of the (discretized) input vertices.
    swaps : bool
        Add_triangle keeps the meshed region a constrained Delaunay triangulation by
        edge swaps (default), so the final mesh is the CDT of its vertices and the
        input edges.
    split_boundary : bool
        Split input edges according to the size (default) or keep them exactly as
        given (the paper's assumption).
    gradation : float
        Bound on how fast the size may grow, per unit of its own length (>= 1).
    close_factor : float
        New_is_preferred refuses R when S, or a vertex R would be joined to, is closer
        than ``close_factor * h`` (a constrained edge: half that).
    smooth : int
        Rounds of smoothing after the front has closed (0: none): each moves every
        vertex Basic_aft created to the mean of its neighbours when that keeps its
        triangles valid, then restores the Delaunay property by edge swaps.  Input
        vertices never move.  ``info['smoothing_moves']`` counts the moves.
    strategy : Strategy, optional
        Subtasks to plug in (see :class:`aftmesh.aft.Strategy`); the Python loop runs
        then, otherwise the compiled one.
    progress : bool or callable, optional
        A progress bar (fraction of the area meshed) on standard error: by default
        shown only when standard error is a terminal and the mesh is large; True or
        False to force it; a callable ``f(fraction)`` to receive the fraction instead.
    min_angle : float or None
        Minimum-angle guarantee in degrees (default 28; 0 or None: off).  After
        smoothing, a last pass refines every triangle with a smaller angle by Delaunay
        refinement (off-centres, and splits of the segments they encroach, at dyadic
        distances from an apex where segments meet below 60 degrees), keeping the mesh
        the CDT of its vertices and the input edges.  Then no triangle has an angle
        below the bound, except triangles forced by an input angle below it (their
        shortest edge joins two input segments that meet at such an angle).  The pass
        is proven to terminate up to about 26.5 degrees and does so in practice up to
        about 33.8, so values above 34 are refused; it is also capped (max_triangles
        wins over the bound; a last-resort cap of 8 insertions per triangle).  With
        ``split_boundary=False`` it splits no input edge and inserts a point only where
        all the triangles it makes meet the bound (the mesh never gets worse; the
        bound may then stay out of reach); with ``greedy`` or ``swaps=False`` it does
        not run.  ``info['min_angle']`` says what it did:
        ``bound``, ``reached`` (no triangle below the bound but the excepted ones),
        ``excepted_triangles``, ``unresolved_triangles``, ``inserted`` (of which
        ``segment_splits`` on segments), ``stopped_by`` (None, 'max_triangles' or
        'insertion_cap') and ``insertion_cap``; None when the pass is off.

    Returns
    -------
    Mesh

    Examples
    --------
    >>> import aftmesh
    >>> from shapely.geometry import Point, box
    >>> domain = box(0, 0, 2, 1).difference(Point(0.5, 0.5).buffer(0.2))
    >>> mesh = aftmesh.generate(domain, size=0.1)
    >>> mesh.quality()["min_angle"] > 20
    True
    >>> abs(mesh.area() - domain.area) < 1e-9
    True
    """
    t_start = time.perf_counter()
    _check_options(order, max_triangles, min_area, close_factor, smooth, strategy,
                   dict(greedy=greedy, swaps=swaps, split_boundary=split_boundary))
    gradation = _real("gradation", gradation, InvalidSizeError)
    min_angle = _min_angle(min_angle)
    if max_triangles is not None:
        max_triangles = min(int(max_triangles), MAX_TRIANGLES)
    if isinstance(size, np.ndarray) and size.ndim == 0:
        size = size.item()
    dom = to_domain(domain, keep_vertices=not split_boundary)
    if len(dom.vertices) < 3:
        raise InvalidDomainError(f"the domain has {len(dom.vertices)} vertices: nothing to mesh")
    lo = dom.vertices.min(axis=0)
    hi = dom.vertices.max(axis=0)
    if isinstance(size, (list, tuple, np.ndarray)):
        if dom.polygons is None:
            raise InvalidSizeError("a list of sizes needs a list of region polygons as the domain")
        size = per_region_size(dom.polygons, size)
    seg = dom.segments
    if len(seg):
        # the shortest input edge at each vertex: the size never asks for more there
        L = np.linalg.norm(dom.vertices[seg[:, 1]] - dom.vertices[seg[:, 0]], axis=1)
        shortest = np.full(len(dom.vertices), np.inf)
        np.minimum.at(shortest, seg[:, 0], L)
        np.minimum.at(shortest, seg[:, 1], L)
        used = np.isfinite(shortest)
        field = make_size_field(size, (lo, hi), dom.vertices[used], shortest[used], gradation)
    else:
        field = make_size_field(size, (lo, hi), gradation=gradation)
    area_hint = dom.area if dom.area else float(np.prod(np.maximum(hi - lo, 1e-300)))
    expected = _expected_triangles(field, area_hint, gradation)
    if not expected <= MAX_TRIANGLES:
        raise InvalidSizeError(
            f"the size (down to {field.h_min:.3g}) asks for about {expected:.3g} triangles "
            f"on a domain of area {area_hint:.3g}: more than the {MAX_TRIANGLES} aftmesh "
            "can number")
    if split_boundary:
        # a triangle has three sides, so more boundary edges than 3 N_max can never be
        # meshed within N_max: refuse before allocating them (the exact minimum,
        # formula (3), is checked once the CDT exists)
        if max_triangles is None:
            cap, limit = 3 * MAX_TRIANGLES, f"the limit of {MAX_TRIANGLES} triangles"
        else:
            cap, limit = 3 * max_triangles, f"max_triangles={max_triangles}"
        verts, segs, src = discretize(dom.vertices, dom.segments, dom.segment_source, field,
                                      max_pieces=cap, limit=limit)
    else:
        verts, segs, src = dom.vertices, dom.segments, dom.segment_source
    t_boundary = time.perf_counter()
    nt_hint = int(min(4e8, expected + 4 * len(verts)))

    def build(verts, segs):
        try:
            return build_cdt(verts, segs, dom.holes, dom.region_points, carve=True,
                             nt_hint=min(nt_hint, 50_000_000))
        except CrossingSegmentsError as err:
            return err

    built = build(verts, segs)
    if split_boundary and (isinstance(built, CrossingSegmentsError) or built.n_split):
        # The domain's edges were noded before the discretization (and a dict's
        # crossings refused), so a crossing now, or a piece running exactly through
        # another vertex, comes from a rounded split point put on or across a segment
        # passing within an ulp or two of it: discretize again without such points.
        verts, segs, src = discretize(dom.vertices, dom.segments, dom.segment_source, field,
                                      clear=snap_tolerance(dom.vertices))
        dom.cleanup.append("left out split points within rounding of other segments")
        built = build(verts, segs)
    if isinstance(built, CrossingSegmentsError):
        # What remains crosses by the rounding of the pieces themselves (two segments
        # apart only at a grazing angle): node those pieces too, and try once more.
        verts, segs, src = node_crossings(verts, segs, src, dom.cleanup,
                                          ring_source=dom.ring_source)
        built = build(verts, segs)
        if isinstance(built, CrossingSegmentsError):
            raise _name_sources(built, dom, verts, segs, src) from None
    kernel = built.kernel
    if dom.polygons is not None:
        comp, probes, corners = kernel.components()
        kernel.set_regions(comp, classify_pieces(dom.polygons, probes, corners))
    n_ext, n_unmeshed, _ = kernel.state_counts()
    if n_unmeshed == 0:
        raise InvalidDomainError(
            "the domain encloses no area (are the segments closed rings? are all regions holes?)")
    if max_triangles is not None and n_unmeshed > max_triangles:
        raise InvalidSizeError(
            f"max_triangles={max_triangles} is below the {n_unmeshed} triangles any "
            "triangulation of this boundary needs (formula (3))")
    if min_area is None:
        min_area = 0.01 * (np.sqrt(3) / 4) * field.h_min ** 2
    kernel.set_size_grid(field.x0, field.y0, field.dx, field.dy, field.h)
    kernel.set_options(order=_ORDERS[order],
                       max_triangles=-1 if max_triangles is None else int(max_triangles),
                       min_area=float(min_area), close_factor=float(close_factor),
                       swaps=bool(swaps), greedy=bool(greedy))
    t_cdt = time.perf_counter()
    compiled = strategy is None or strategy.is_builtin
    if compiled:
        kernel.convert_to_frontal_edge_set()
        bar = _progress_callback(progress, nt_hint)
        try:
            kernel.run(progress=bar)
        finally:
            if isinstance(bar, _ProgressBar):
                bar.close()
    else:
        basic_aft(kernel, strategy)
        if kernel.counters()["unmeshed"] != 0:
            raise InvalidOptionError(
                "the strategy's get_next_edge returned -1 while front edges remained")
    moves = 0
    if smooth:
        moves = kernel.smooth(len(verts), int(smooth))
    refined = None
    if min_angle and swaps and not greedy:
        refined = kernel.refine(min_angle, len(dom.vertices), split_segments=split_boundary)
        refined = {"bound": min_angle, "reached": refined["unresolved_triangles"] == 0,
                   **refined}
    t_aft = time.perf_counter()
    a = kernel.arrays()
    to_out = a["vertex_map"][built.merged]
    pieces = segment_markers(a["points"], a["segments"], built.vertices, built.segments, to_out)
    markers = np.where(pieces >= 0, src[np.maximum(pieces, 0)], -1).astype(np.int32)
    if dom.source_markers is not None:
        markers = np.where(markers >= 0, dom.source_markers[np.maximum(markers, 0)], -1)
    counters = kernel.counters()
    info = {
        "merged_vertices": built.n_merged,
        "cleanup": dom.cleanup,
        "sources": dom.source_names,
        "new_vertices": counters["new_vertices"],
        # Update_internal calls where T(E, R) was not already a CDT triangle after
        # inserting R, so F and G were inserted by retriangulation (Lemma 3.1 says 0)
        "forced_edges": counters["forced_edges"],
        "smoothing_moves": moves,
        "min_angle": refined,
        "compiled_loop": compiled,
        "size_field": field,
        "timing": {"boundary": t_boundary - t_start, "cdt": t_cdt - t_boundary,
                   "basic_aft": t_aft - t_cdt, "total": time.perf_counter() - t_start},
    }
    return Mesh._adopt(points=a["points"], triangles=a["triangles"], neighbors=a["neighbors"],
                segments=a["segments"], regions=a["regions"], segment_markers=markers,
                info=info)
