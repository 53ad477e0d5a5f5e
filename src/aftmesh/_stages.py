"""The stages of one :func:`aftmesh.generate` call, in the order it runs them.

Each stage is one step of ARCHITECTURE.md's data flow: the size field, the discretized
boundary and its CDT (with the retry policy for rounding), the kernel made ready for
the front, the front itself, smoothing, and the :class:`~aftmesh.mesh.Mesh`.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

from ._kernel import bounding_box, shortest_edges, size_field_count, take_or_none
from .aft import basic_aft
from .boundary import discretize
from .domain import Domain, classify_pieces, node_crossings, snap_tolerance
from .errors import CrossingSegmentsError, InvalidDomainError, InvalidOptionError, InvalidSizeError
from .mesh import Mesh
from .noding import vertices_first
from .options import MAX_TRIANGLES, ORDERS, Options
from .pslg import BuiltCDT, build_cdt
from .sizing import SizeField, make_size_field, per_region_size
from .tags import resolve_boundary_tags, segment_tags

# Area of an equilateral triangle of side h, over h^2 (sqrt(3) / 4, rounded as the
# triangle-count estimate has always used it: the estimate feeds allocation hints).
EQUILATERAL_AREA = 0.43
# The count estimate's smallest growth rate: with no gradation limit the graded-disk
# bound of _expected_triangles would be infinite.
MIN_ESTIMATE_RATE = 0.05
# The estimate is rough; overshooting it a little costs less than regrowing arrays.
ESTIMATE_MARGIN = 1.2
# The triangle-count hint stays below what int32 half-edge indices (3 per triangle)
# can number.
MAX_TRIANGLE_HINT = 4e8
# Up-front allocation is capped: arrays grow by doubling anyway, and an overestimate
# must not reserve gigabytes before the first triangle.
MAX_PREALLOCATED = 50_000_000
# A progress bar is worth drawing only for meshes that take seconds.
PROGRESS_MIN_TRIANGLES = 200_000
# Default A_min (formula (5)): this fraction of the smallest size's equilateral
# triangle, small enough never to refuse a point the size asks for.
MIN_AREA_FRACTION = 0.01


class _ProgressBar:
    """A one-line bar on standard error, redrawn only when the percentage changes."""

    WIDTH = 30

    def __init__(self, stream):
        self.stream = stream
        self.last = -1

    def __call__(self, fraction: float) -> None:
        pct = int(100 * min(max(fraction, 0.0), 1.0))
        if pct != self.last:
            self.last = pct
            filled = pct * self.WIDTH // 100
            bar = "#" * filled + "." * (self.WIDTH - filled)
            self.stream.write(f"\raftmesh [{bar}] {pct:3d}%")
            self.stream.flush()

    def close(self) -> None:
        if self.last >= 0:
            self.stream.write("\r" + " " * (self.WIDTH + 18) + "\r")
            self.stream.flush()


def default_bar_limit() -> float:
    """The expected triangle count above which progress=None draws a bar:
    PROGRESS_MIN_TRIANGLES when standard error is a terminal, else never (inf), also
    when there is no usable standard error (None under pythonw, closed, or an object
    without isatty)."""
    try:
        terminal = sys.stderr.isatty()
    except (AttributeError, ValueError, OSError):
        terminal = False
    return PROGRESS_MIN_TRIANGLES if terminal else math.inf


def _progress_callback(progress, expected_triangles: int):
    if callable(progress):
        return progress
    if progress is None:
        # the size first: isatty is a system call, and most meshes are small
        progress = (
            expected_triangles > PROGRESS_MIN_TRIANGLES and expected_triangles > default_bar_limit()
        )
    return _ProgressBar(sys.stderr) if progress else None


def expected_triangles(field: SizeField, area: float, gradation: float) -> float:
    """About how many triangles the size field asks for on `area`: the integral of
    1 / (equilateral area of h) over the background's triangles, scaled to the
    domain's share of them (the kernel's size_field_count says how it counts)."""
    if field.is_constant:
        h = float(field.constant)  # > 0; Python floats overflow to inf as numpy's do
        return float(area) / (EQUILATERAL_AREA * h) / h
    # compiled arithmetic returning Python floats: an overflow is inf, never a warning
    total, covered = size_field_count(*field.kernel_args(), MIN_ESTIMATE_RATE, EQUILATERAL_AREA)
    return float(total * min(1.0, area / max(covered, 1e-300)) * ESTIMATE_MARGIN)


def size_field(
    dom: Domain, size, gradation: float, kept_whole: bool = False
) -> tuple[SizeField, float]:
    """The size field over the domain, and the number of triangles it asks for.

    The user's size is combined with the shortest input edge at each vertex: the size
    never asks for more than that edge there.  With the input edges kept whole
    (``kept_whole``, split_boundary=False), a vertex where two edges meet at a wide
    angle asks for the geometric mean of their lengths instead (the kernel's
    ``shortest_edges`` says why)."""
    if isinstance(size, np.ndarray) and size.ndim == 0:
        size = size.item()
    lo, hi = bounding_box(np.ascontiguousarray(dom.vertices, dtype=np.float64))
    if isinstance(size, (list, tuple, np.ndarray)):
        if dom.polygons is None:
            raise InvalidSizeError("a list of sizes needs a list of region polygons as the domain")
        size = per_region_size(dom.polygons, size)
    seg = dom.segments
    if len(seg):
        verts = np.ascontiguousarray(dom.vertices, dtype=np.float64)
        shortest = shortest_edges(verts, np.ascontiguousarray(seg, dtype=np.int32), kept_whole)
        used = np.isfinite(shortest)
        if not used.all():  # a lone point: no edge there
            verts, shortest = verts[used], shortest[used]
        field = make_size_field(size, (lo, hi), verts, shortest, gradation)
    else:
        field = make_size_field(size, (lo, hi), gradation=gradation)
    area = dom.area or max(hi[0] - lo[0], 1e-300) * max(hi[1] - lo[1], 1e-300)
    expected = expected_triangles(field, area, gradation)
    if not expected <= MAX_TRIANGLES:
        raise InvalidSizeError(
            f"the size (down to {field.h_min:.3g}) asks for about {expected:.3g} triangles "
            f"on a domain of area {area:.3g}: more than the {MAX_TRIANGLES} aftmesh "
            "can number"
        )
    return field, expected


@dataclass
class Boundary:
    """The discretized boundary and the kernel holding its CDT."""

    built: BuiltCDT
    vertices: np.ndarray
    segments: np.ndarray
    source: np.ndarray  # input edge of each segment (see Domain.segment_edge)
    triangle_hint: int


def _name_sources(err: CrossingSegmentsError, dom: Domain, verts, segs, edge):
    """The same error naming the user's segments / rings, not the pieces the
    discretization made of them."""
    src = dom.edge_source[edge]
    names = [dom.source_names[src[k]] for k in err.segments if 0 <= k < len(src)]
    where = [verts[segs[k]].tolist() for k in err.segments if 0 <= k < len(src)]
    detail = " and ".join(f"{n} (near {w[0]} -> {w[1]})" for n, w in zip(names, where))
    return CrossingSegmentsError(
        f"these input edges cross: {detail}", tuple(int(src[k]) for k in err.segments)
    )


def boundary_cdt(dom: Domain, field: SizeField, opts: Options, expected: float) -> Boundary:
    """Split the input edges by the size and build their CDT in the kernel.

    The domain's edges were noded before the discretization (and a dict's crossings
    refused), so a crossing now, or a piece running exactly through another vertex,
    comes from a rounded split point put on or across a segment passing within an
    ulp or two of it: then discretize again without such points.  What still crosses
    after that does so by the rounding of the pieces themselves (two segments apart
    only at a grazing angle): node those pieces too, and try once more."""
    if opts.split_boundary:
        # a triangle has three sides, so more boundary edges than 3 N_max can never
        # be meshed within N_max: refuse before allocating them (the exact minimum,
        # formula (3), is checked once the CDT exists)
        cap, limit = opts.triangle_cap
        verts, segs, edge = discretize(
            dom.vertices, dom.segments, dom.segment_edge, field, max_pieces=3 * cap, limit=limit
        )
    else:
        verts, segs, edge = dom.vertices, dom.segments, dom.segment_edge
    hint = int(min(MAX_TRIANGLE_HINT, expected + 4 * len(verts)))

    def build(verts, segs):
        try:
            return build_cdt(
                verts,
                segs,
                dom.holes,
                dom.region_points,
                carve=True,
                nt_hint=min(hint, MAX_PREALLOCATED),
            )
        except CrossingSegmentsError as err:
            return err

    built = build(verts, segs)
    if opts.split_boundary and (isinstance(built, CrossingSegmentsError) or built.n_split):
        verts, segs, edge = discretize(
            dom.vertices, dom.segments, dom.segment_edge, field, clear=snap_tolerance(dom.vertices)
        )
        dom.cleanup.append("left out split points within rounding of other segments")
        built = build(verts, segs)
    if isinstance(built, CrossingSegmentsError):
        verts, segs, edge = node_crossings(
            verts, segs, edge, dom.cleanup, ring_source=dom.edge_is_ring
        )
        verts, segs = vertices_first(dom.vertices, verts, segs)
        built = build(verts, segs)
        if isinstance(built, CrossingSegmentsError):
            raise _name_sources(built, dom, verts, segs, edge) from None
    return Boundary(built, verts, segs, edge, hint)


def prepare_front(boundary: Boundary, dom: Domain, field: SizeField, opts: Options):
    """Give the CDT's pieces their regions, check the domain has area and fits
    max_triangles, and hand the size field and options to the kernel."""
    kernel = boundary.built.kernel
    # one polygon whose one ring is the only source: the carve left one piece, in
    # region 0 already (every triangle starts there)
    if dom.polygons is not None and not (len(dom.polygons) == 1 and len(dom.source_names) == 1):
        comp, probes, corners = kernel.components()
        kernel.set_regions(comp, classify_pieces(dom.polygons, probes, corners))
    _, n_unmeshed, _ = kernel.state_counts()
    if n_unmeshed == 0:
        raise InvalidDomainError(
            "the domain encloses no area (are the segments closed rings? are all regions holes?)"
        )
    if opts.max_triangles is not None and n_unmeshed > opts.max_triangles:
        raise InvalidSizeError(
            f"max_triangles={opts.max_triangles} is below the {n_unmeshed} triangles any "
            "triangulation of this boundary needs (formula (3))"
        )
    min_area = opts.min_area
    if min_area is None:
        min_area = MIN_AREA_FRACTION * (math.sqrt(3) / 4) * field.h_min**2
    kernel.set_size_field(*field.kernel_args())
    kernel.set_options(
        order=ORDERS[opts.order],
        max_triangles=-1 if opts.max_triangles is None else opts.max_triangles,
        min_area=float(min_area),
        close_factor=opts.close_factor,
        swaps=opts.swaps,
        greedy=opts.greedy,
        scaffold=opts.scaffold,
    )
    return kernel


def run_front(kernel, opts: Options, triangle_hint: int) -> None:
    """Basic_aft until the front is empty: the compiled loop without the GIL, or the
    Python loop when the strategy overrides a subtask."""
    if opts.compiled:
        kernel.convert_to_frontal_edge_set()
        bar = _progress_callback(opts.progress, triangle_hint)
        try:
            kernel.run(progress=bar)
        finally:
            if isinstance(bar, _ProgressBar):
                bar.close()
        return
    assert opts.strategy is not None  # the compiled loop returned above otherwise
    basic_aft(kernel, opts.strategy)
    if kernel.counters()["unmeshed"] != 0:
        raise InvalidOptionError(
            "the strategy's get_next_edge returned -1 while front edges remained"
        )


def smooth(kernel, boundary: Boundary, dom: Domain, opts: Options) -> int:
    """Smoothing rounds after the front has closed; the number of vertex moves.  The
    input vertices (numbered first) never move; the points that split an input edge
    (numbered next, up to the discretized boundary's end) slide along it with
    slide_boundary, else stay.  From 3 rounds on the valence splits may add vertices
    after Basic_aft's (kernel.counters()["valence_splits"])."""
    if not opts.smooth:
        return 0
    n_corners = len(dom.vertices) if opts.slides else -1
    return kernel.smooth(len(boundary.vertices), opts.smooth, n_corners=n_corners)


def refine(kernel, boundary: Boundary, dom: Domain, opts: Options) -> dict | None:
    """The minimum-angle pass after smoothing (none with greedy, without swaps, or with
    min_angle off); what it did, for info["min_angle"].  With split_boundary=False it
    splits no input edge and inserts only points whose triangles all meet the bound.
    With smoothing on, the vertices around its new ones settle and the pass runs
    again (refine.pxi's refine_settled)."""
    if not opts.min_angle or opts.greedy or not opts.swaps:
        return None
    done = kernel.refine(
        opts.min_angle,
        len(dom.vertices),
        split_segments=opts.split_boundary,
        smooth_rounds=opts.smooth,
        first_movable=len(boundary.vertices),
        slide=opts.slides,
    )
    return {"bound": opts.min_angle, "reached": done["unresolved_triangles"] == 0, **done}


def timing(
    t_start: float, t_boundary: float, t_cdt: float, t_aft: float, t_refine: float
) -> dict[str, float]:
    """info["timing"] from the times the stages ended (perf_counter), without total."""
    return {
        "boundary": t_boundary - t_start,
        "cdt": t_cdt - t_boundary,
        "basic_aft": t_aft - t_cdt,
        "min_angle": t_refine - t_aft,
    }


def _lookup(table: np.ndarray, index: np.ndarray) -> np.ndarray:
    """table[index] as int32, -1 where index is -1 (the kernel's and the domain's
    "none"; no index is below that)."""
    return take_or_none(
        np.ascontiguousarray(table, dtype=np.int32), np.ascontiguousarray(index, dtype=np.int32)
    )


def assemble(
    kernel,
    source: np.ndarray,
    n_merged: int,
    dom: Domain,
    field: SizeField,
    opts: Options,
    moves: int,
    timing: dict,
    edge_tags=None,
    refined: dict | None = None,
) -> Mesh:
    """The Mesh: the kernel's compact arrays; for each segment its input edge
    (segment_sources), its marker (the user's ring / line / segment it lies on, or
    that source's own marker) and its boundary tag; and what happened.  `source`:
    the input edge of each boundary piece (Boundary.source); `n_merged`: the input
    vertices merged into others (BuiltCDT.n_merged)."""
    a = kernel.arrays(release=True)  # the kernel is not used after this
    pieces = a["segment_ids"]  # the kernel's provenance of each output segment
    edges = _lookup(source, pieces)
    markers = _lookup(dom.edge_source, edges)
    if dom.source_markers is not None:
        markers = _lookup(dom.source_markers, markers)
    counters = kernel.counters()
    info = {
        "merged_vertices": n_merged,
        "cleanup": dom.cleanup,
        "sources": dom.source_names,
        "new_vertices": counters["new_vertices"],
        # Update_internal calls where T(E, R) was not already a CDT triangle after
        # inserting R, so F and G were inserted by retriangulation (Lemma 3.1 says 0)
        "forced_edges": counters["forced_edges"],
        # points smoothing inserted beside vertices of eight triangles or more
        "valence_splits": counters["valence_splits"],
        # temporary vertices planted in the unmeshed region, and those that could not
        # be removed again (ordinary vertices of the mesh)
        "scaffold": counters["scaffold"],
        "scaffold_kept": counters["scaffold_kept"],
        "smoothing_moves": moves,
        "min_angle": refined,
        "compiled_loop": opts.compiled,
        "size_field": field,
        "timing": timing,
        **dom.report,
    }
    tags, names = None, {}
    if edge_tags is not None:
        tags, names = segment_tags(edge_tags[0], edges), edge_tags[1]
    return Mesh._adopt(
        points=a["points"],
        triangles=a["triangles"],
        neighbors=a["neighbors"],
        segments=a["segments"],
        regions=a["regions"],
        segment_markers=markers,
        segment_sources=edges,
        segment_tags=tags,
        tag_names=names,
        info=info,
    )


def boundary_tags(dom: Domain, opts: Options):
    """(tag of each input edge, {name: tag}) from the boundary_tags option, or None.
    Resolved before any meshing, so a bad selector fails fast."""
    if opts.boundary_tags is None:
        return None
    assert dom.edge_midpoints is not None  # both Domain constructors set it
    return resolve_boundary_tags(
        opts.boundary_tags,
        dom.edge_midpoints,
        describe=lambda e: dom.source_names[dom.edge_source[e]],
    )
