"""generate's common case in one kernel call.

With the compiled subtasks, whatever the domain (one polygon, with or without
holes, polygons, a list of regions, constraint lines and points, a dict or .poly) and
whatever the size (a number, None, a callable, one per region, a SizeField), the
stages of :mod:`aftmesh._stages` from the size field to the refined mesh run as one
compiled call (``cython_ext/pipeline.pxi``), which applies the stages' rules in the
same order, so the mesh is the one they make; the pieces of polygons that the
exterior ring or their nesting do not classify are classified by the stages' own
probes, asked from the call.  Whatever that call does not reproduce (a retry for
rounding, a progress bar, an error message), it declines, and generate runs the
stages instead.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from functools import partial

import numpy as np
from shapely.geometry import Polygon

from . import _stages
from ._kernel import COMMON_RULE_COUNT, generate_common
from ._order import round_keys
from .boundary import MAX_SAMPLES
from .domain_record import Domain
from .mesh import Mesh
from .options import MAX_TRIANGLES, ORDERS, Options
from .pslg import fractional_markers, markers_out_of_range
from .regions import classify_pieces
from .sizing import (
    BOUNDARY_REACH,
    BOX_PAD,
    CONSTANT_IF_EDGES_ABOVE,
    DEFAULT_GRADATION,
    MIN_SIZE_ULPS,
    SizeField,
)

__all__ = ["common_case"]

# The rules of sizing.py and _stages.py, in pipeline.pxi's RULE_* order.
_RULES = np.array(
    [
        CONSTANT_IF_EDGES_ABOVE,
        BOX_PAD,
        MIN_SIZE_ULPS,
        DEFAULT_GRADATION,
        BOUNDARY_REACH,
        _stages.EQUILATERAL_AREA,
        _stages.MIN_ESTIMATE_RATE,
        _stages.ESTIMATE_MARGIN,
        MAX_TRIANGLES,
        _stages.MAX_TRIANGLE_HINT,
        _stages.MAX_PREALLOCATED,
        MAX_SAMPLES,
        # the default A_min over h_min^2, as prepare_front groups it
        _stages.MIN_AREA_FRACTION * (math.sqrt(3) / 4),
    ],
    dtype=np.float64,
)
assert len(_RULES) == COMMON_RULE_COUNT
_RULES.setflags(write=False)


def _points(rows: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(rows, dtype=np.float64)


# A double holds every integer below this exactly: a larger int size takes the stages
# (whose float() of it the compiled call would not reproduce past it).
_EXACT_INT = 2**53


def _is_plain_number(size) -> bool:
    """A float or an int that a double holds exactly, above 0 and finite: the stages
    refuse the others, with their message (the compiled call reads 0 as size=None)."""
    if type(size) is float:
        return 0.0 < size < math.inf
    return type(size) is int and 0 < size < _EXACT_INT


def applies(dom: Domain, size, opts: Options) -> bool:
    """Whether the compiled call may take this generate call: a plain number size or
    None (the input edges' lengths), or a field (a size callable, a SizeField, a size
    per region) that _stages.size_field makes first (see given_field), the compiled
    subtasks (input edges split or kept whole), no progress bar asked for, and any
    domain: one polygon of rings (holes allowed; its pieces told by the exterior
    ring), a multipolygon proved valid (by how its pieces nest), other polygons (a
    list of regions, constraint lines and points: by the stages' probes), or a dict
    or .poly (Triangle's hole and region points allowed)."""
    return (
        (size is None or _is_plain_number(size) or given_field(size))
        and opts.compiled
        and (opts.progress is None or opts.progress is False)
        and _plain_markers(dom.region_points)
    )


def given_field(size) -> bool:
    """A size the compiled call takes as the field _stages.size_field makes of it (a
    callable, the field itself when a SizeField, a size per region), not as a
    number: generate builds that field before the call, once, and hands it to the
    stages if the call declines (the user's callable is not evaluated twice)."""
    return (
        callable(size)
        or isinstance(size, (list, tuple))
        or (isinstance(size, np.ndarray) and size.ndim == 1)
    )


def _plain_markers(region_points: np.ndarray | None) -> bool:
    """No region points, or region markers that pslg.build_cdt takes as they are
    (whole numbers in the int32 range; it refuses the others, naming them)."""
    if region_points is None or len(region_points) == 0:
        return True
    markers = region_points[:, 2]
    return not (fractional_markers(markers).any() or markers_out_of_range(markers).any())


def _one_polygon_of_rings(dom: Domain) -> bool:
    """One polygon whose rings are all the sources (no constraint lines): its pieces
    are classified without probes (pipeline.pxi's _inside_exterior)."""
    polygons = dom.polygons
    assert polygons is not None
    return (
        len(polygons) == 1 and type(polygons[0]) is Polygon and dom.n_rings == len(dom.source_names)
    )


def _by_probes(dom: Domain) -> Callable | None:
    """generate_common's classify_cb for polygons whose pieces neither the exterior
    ring nor their nesting classifies (a list of regions sharing edges, a multipolygon
    the kernel did not prove, constraint lines and points): each piece's region from
    its probe, as _stages.prepare_front asks regions.classify_pieces; else None."""
    polygons = dom.polygons
    if polygons is None or _one_polygon_of_rings(dom) or _nested_rings(dom):
        return None
    return partial(classify_pieces, polygons)


def _nested_rings(dom: Domain) -> bool:
    """Polygons whose rings are all the sources and are proved to meet nowhere: their
    pieces are classified by how they nest (domain.pxi's nested_regions)."""
    return dom.ring_polygon is not None and dom.n_rings == len(dom.source_names)


def _progress_limit(progress) -> float:
    """The triangle hint above which the stages would draw a progress bar (the
    compiled call declines there): never when progress is False."""
    return math.inf if progress is False else _stages.default_bar_limit()


def common_case(
    dom: Domain, size, opts: Options, edge_tags, t_start: float, expected: float = -1.0
) -> Mesh | None:
    """The Mesh of generate by the compiled call, or None where it declines (then
    nothing has changed, and the stages run).  The caller checked `applies`; size is a
    number, None, or the SizeField _stages.size_field made (given_field), with the
    triangles it asks for, `expected`, as that counted them."""
    given = size.kernel_args()[1:] if isinstance(size, SizeField) else None
    if given is not None:
        constant = float(size.constant) if size.is_constant else 0.0
    else:
        constant = 0.0 if size is None else float(size)  # 0: the size from the input edges
    refining = bool(opts.min_angle) and not opts.greedy and opts.swaps
    seeds = dom.region_points if dom.region_points is not None and len(dom.region_points) else None
    cap, _ = opts.triangle_cap
    by_probes = _by_probes(dom)
    out = generate_common(
        np.ascontiguousarray(dom.vertices, dtype=np.float64),
        np.ascontiguousarray(dom.segments, dtype=np.int32),
        np.ascontiguousarray(dom.segment_edge, dtype=np.int32),
        np.ascontiguousarray(dom.edge_source, dtype=np.int32),
        # holes or parts: pieces to classify (by probes: see below)
        dom.polygons is not None and dom.n_rings > 1 and by_probes is None,
        dom.ring_polygon,
        None if dom.holes is None or len(dom.holes) == 0 else _points(dom.holes),
        None if seeds is None else _points(seeds[:, :2]),
        None if seeds is None else seeds[:, 2].astype(np.int32),
        constant,
        float(opts.gradation),
        float(dom.area or 0.0),
        round_keys,
        _RULES,
        float(3 * cap),  # boundary_cdt's bound on the pieces
        _progress_limit(opts.progress),
        int(ORDERS[opts.order]),
        -1 if opts.max_triangles is None else opts.max_triangles,
        opts.min_area,
        opts.close_factor,
        opts.swaps,
        opts.greedy,
        opts.smooth,
        opts.slides,
        float(opts.min_angle) if refining else 0.0,
        opts.scaffold,
        opts.split_boundary,
        given,
        float(expected) if given is not None else -1.0,
        by_probes,
    )
    if out is None:
        return None
    kernel, source, _n_boundary, n_merged, arrays, _expected, moves, done, times = out
    t_boundary, t_cdt, t_aft = times
    if given is not None:
        field = size
    else:
        field = SizeField(constant) if arrays is None else SizeField(constant, *arrays)
    refined = None
    if done is not None:
        refined = {"bound": opts.min_angle, "reached": done["unresolved_triangles"] == 0, **done}
    t_refine = time.perf_counter()
    timing = _stages.timing(t_start, t_boundary, t_cdt, t_aft, t_refine)
    mesh = _stages.assemble(
        kernel, source, n_merged, dom, field, opts, moves, timing, edge_tags, refined
    )
    timing["total"] = time.perf_counter() - t_start
    return mesh
