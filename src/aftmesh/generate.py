"""``aftmesh.generate``: a quality triangle mesh of a domain by Basic_aft.

The body is the data flow of ARCHITECTURE.md, one stage per call (see ``_stages``);
the common case runs those stages as one compiled call (see ``_common``).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, overload

from . import _common, _stages
from ._typing import DomainArg, PathArg, SizeArg
from .aft import Strategy
from .domain import to_domain
from .errors import InvalidDomainError
from .mesh import Mesh
from .options import DEFAULT_MIN_ANGLE, Options, check_options
from .sizing import DEFAULT_GRADATION

__all__ = ["generate"]

# generate's keyword options checked by options.check_options; a partitioned run passes
# them on (partition.py decides which reach the parts and which only the run that
# discretizes the whole boundary)
_OPTIONS = (
    "max_triangles",
    "min_area",
    "order",
    "greedy",
    "swaps",
    "split_boundary",
    "gradation",
    "close_factor",
    "smooth",
    "slide_boundary",
    "strategy",
    "progress",
    "repair",
    "tolerance",
    "boundary_tags",
    "min_angle",
    "scaffold",
)


@overload
def generate(
    domain: DomainArg,
    size: SizeArg = None,
    *,
    max_triangles: int | None = None,
    min_area: float | None = None,
    order: str = "shortest",
    greedy: bool = False,
    swaps: bool = True,
    split_boundary: bool = True,
    gradation: float = DEFAULT_GRADATION,
    close_factor: float = 0.5,
    smooth: int = 4,
    slide_boundary: bool = True,
    strategy: Strategy | None = None,
    progress: bool | Callable[[float], object] | None = None,
    repair: bool = False,
    tolerance: float = 0.0,
    boundary_tags: Mapping[str, Any] | None = None,
    min_angle: float | None = DEFAULT_MIN_ANGLE,
    scaffold: bool = True,
    partitions: int | None = None,
    client: Any = None,
    out: None = None,
) -> Mesh: ...


@overload
def generate(
    domain: DomainArg,
    size: SizeArg = None,
    *,
    max_triangles: int | None = None,
    min_area: float | None = None,
    order: str = "shortest",
    greedy: bool = False,
    swaps: bool = True,
    split_boundary: bool = True,
    gradation: float = DEFAULT_GRADATION,
    close_factor: float = 0.5,
    smooth: int = 4,
    slide_boundary: bool = True,
    strategy: Strategy | None = None,
    progress: bool | Callable[[float], object] | None = None,
    repair: bool = False,
    tolerance: float = 0.0,
    boundary_tags: Mapping[str, Any] | None = None,
    min_angle: float | None = DEFAULT_MIN_ANGLE,
    scaffold: bool = True,
    partitions: int | None = None,
    client: Any = None,
    out: PathArg,
) -> Path: ...


def generate(
    domain: DomainArg,
    size: SizeArg = None,
    *,
    max_triangles: int | None = None,
    min_area: float | None = None,
    order: str = "shortest",
    greedy: bool = False,
    swaps: bool = True,
    split_boundary: bool = True,
    gradation: float = DEFAULT_GRADATION,
    close_factor: float = 0.5,
    smooth: int = 4,
    slide_boundary: bool = True,
    strategy: Strategy | None = None,
    progress: bool | Callable[[float], object] | None = None,
    repair: bool = False,
    tolerance: float = 0.0,
    boundary_tags: Mapping[str, Any] | None = None,
    min_angle: float | None = DEFAULT_MIN_ANGLE,
    scaffold: bool = True,
    partitions: int | None = None,
    client: Any = None,
    out: PathArg | None = None,
) -> Mesh | Path:
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
        Target edge length: a number; a callable ``f(x, y)``; one number per region
        (with a sequence of polygons as the domain); or None to take it from the
        lengths of the input edges.  The callable is called a few times, each time
        with two 1-D float arrays ``x``, ``y`` of equal length (many points at once,
        never one call per point), and must return an array of that length (one size
        per point) or a single number; any other shape raises InvalidSizeError.  So
        ``lambda x, y: h(np.c_[x, y])`` works for any ``h`` taking (n, 2) points.
        A size must span at least 64 units in the last place of the largest
        coordinate (about 1e-14 of it); a finer one raises InvalidSizeError.
    max_triangles : int, optional
        N_max: the mesh never has more triangles (formula (4) of the paper).
    min_area : float, optional
        A_min: no new vertex whose triangle would be smaller (formula (5)).  By default
        1 % of the area of an equilateral triangle of the smallest size.
    order : {'shortest', 'longest', 'oldest'}
        Get_next_edge: shortest front edge first (default; the edges on the input
        segments, shortest first, come before every edge made since, so the first
        row along the whole boundary is in place before rows from elsewhere reach
        it), longest first, or oldest first (layer by layer).
    greedy : bool
        New_is_preferred always false: no point is added and the result is a
        triangulation of the (discretized) input vertices.
    swaps : bool
        Add_triangle keeps the meshed region a constrained Delaunay triangulation by
        edge swaps (default), so the final mesh is the CDT of its vertices and the
        input edges.
    split_boundary : bool
        Split input edges according to the size (default) or keep them exactly as
        given (the paper's assumption).  Kept whole, a vertex where two input edges
        meet at more than 60 degrees asks for the geometric mean of their lengths
        rather than the shorter one: the longer edge cannot be split to match it.
    gradation : float
        Bound on how fast the size may grow, per unit of its own length (>= 1).
    close_factor : float
        New_is_preferred refuses R when S, or a vertex R would be joined to, is closer
        than ``close_factor * h`` (a constrained edge it would face: 0.65 times that, so
        fronts closer than about 1.2 h connect across).  ``h`` is the local size, but
        at most 1.5 times the side of R's triangle where the size is well above the
        front edge (short input edges), and 1.2 times that where the size is uniform
        and the apex of R's edge is not an input vertex (it keeps the seams where two
        fronts' lattices meet one triangle wide).  Where the size is one constant and
        R's edge is shorter than 0.8 of it (fronts converging, as in a disc), ``h``
        rises to 1.6 times the size, but no further than makes ``close_factor * h``
        the edge's length, so the rows merge their points instead of compressing.
        The reach ``close_factor * h`` stays below 0.95 times R's side, the distance
        of R's lattice neighbours (the default reaches 0.9 of it at most): a larger
        close_factor cannot make the front refuse a uniform lattice's own points, and
        values from about 1 up act alike.
    smooth : int
        Rounds of smoothing after the front has closed (0: none).  Each round tries,
        for every vertex Basic_aft created whose triangles are not all nearly
        equilateral, the mean of its neighbours, and the last round (and every round
        next to a triangle of shape below 0.85) also up to four steps along the
        gradient, and moves it to the place that lowers the sum of 1/shape^2
        of its triangles without making the worst of them worse, keeping every triangle
        counter-clockwise (exact); edge swaps around it then restore the constrained
        Delaunay property.  With ``slide_boundary``, a point that splits an input
        edge is judged the same way, but only along its input edge, so the domain
        does not change.  With 3 rounds or more, edges are flipped after the
        first round towards six triangles at every vertex (where fronts met,
        smoothing alone leaves vertices of five and seven), the second round lets
        the vertices settle without swaps, and the swaps then make the mesh a CDT
        again; a vertex still in eight triangles or more, which no flip helps, gets
        a new point a quarter of the way along its longest edge (before the first
        round, and after the last followed by rounds from the new points), each
        adding two triangles within ``max_triangles``.  Input vertices never move.
        ``info['smoothing_moves']`` counts the moves, ``info['valence_splits']``
        the points added.
    slide_boundary : bool
        Let smoothing slide the points that split an input edge along it (default):
        the discretization's, and the minimum-angle pass's where the mesh settles
        after it.  False keeps them where they were put, whatever the interior's mesh
        (the minimum-angle pass may still split a piece).  Never with
        ``greedy`` (its mesh is the CDT of the discretized boundary), and a run in
        more than one part never slides them, since its parts share them.
    strategy : Strategy, optional
        Subtasks to plug in (see :class:`aftmesh.aft.Strategy`); the Python loop runs
        then, otherwise the compiled one.
    progress : bool or callable, optional
        A progress bar (fraction of the area meshed) on standard error: by default
        shown only when standard error is a terminal and the mesh is large; True or
        False to force it; a callable ``f(fraction)`` to receive the fraction instead.
    repair : bool
        Make invalid polygons valid first with ``shapely.make_valid`` (shapely,
        ring or sequence-of-polygons input): the polygonal part is meshed, the
        zero-width slivers it produces are dropped, constraint lines and points in
        or on the repaired domain are kept, and ``info['repair']`` lists what was
        repaired (``'repaired'``) and dropped (``'dropped'``).  Default False: an
        invalid polygon raises InvalidDomainError naming the ring at fault.
    tolerance : float
        Absolute distance below which vertices are merged and a constraint line's
        end or bend (a dict's segment end used by no other segment) is snapped onto a
        segment it nearly touches; ``info['tolerance']`` counts what it changed
        (``'merged'``, ``'snapped'``) and ``info['cleanup']`` says so.  Default 0:
        exact, only exact duplicates merge.  Vertices on a straight run of a ring are
        kept either way.
    boundary_tags : mapping, optional
        Names for parts of the boundary: ``{name: selector}``, the selector either a
        callable ``f(x, y) -> bool array`` (called once, on the midpoints of all
        input edges as 1-D arrays) or a sequence of input-edge indices (numbered as
        ``Mesh.segment_sources``).  Tags are numbered 1, 2, ... in mapping order;
        the mesh gets ``segment_tags`` and ``tag_names``, and
        ``mesh.boundary_facets(name)`` returns the segments of a name.  An edge
        selected by two names raises InvalidOptionError.
    min_angle : float or None
        Minimum-angle guarantee in degrees (default 28; 0 or None: off).  After
        smoothing, a last pass refines every triangle with a smaller angle by Delaunay
        refinement (off-centres, and splits of the segments they encroach, at dyadic
        distances from an apex where segments meet below 60 degrees), keeping the mesh
        the CDT of its vertices and the input edges.  With smoothing on, the vertices
        around the points it added then get two smoothing rounds (its splits sliding
        along their segments, see ``slide_boundary``) and the pass runs again.  Then
        no triangle has an angle below the bound, except triangles forced by an input
        angle below it (their shortest edge joins two input segments that meet at such
        an angle).  The pass is proven to terminate up to about 26.5 degrees and does
        so in practice up to about 33.8, so values above 34 are refused; it is also
        capped (max_triangles wins over the bound; a last-resort cap of 8 insertions
        per triangle), and leaves triangles with an edge shorter or a height smaller
        than 4096 ulps of the largest coordinate (a region or gap that narrow) as
        they are, counted as unresolved.  With ``split_boundary=False`` it splits no
        input edge and inserts a point only where all the triangles it makes meet the
        bound (the mesh never gets worse; the bound may then stay out of reach); with
        ``greedy`` or ``swaps=False`` it does not run.  ``info['min_angle']`` says what it did:
        ``bound``, ``reached`` (no triangle below the bound but the excepted ones),
        ``excepted_triangles``, ``unresolved_triangles``, ``inserted`` (of which
        ``segment_splits`` on segments; both runs together), ``stopped_by`` (None,
        'max_triangles' or 'insertion_cap') and ``insertion_cap``; None when the pass
        is off.
    scaffold : bool
        Plant a sparse lattice of temporary points (8 sizes apart, kept 4 sizes from
        the boundary) in the unmeshed region before the front starts, and remove each
        one before the front reaches it.  The unmeshed triangles then stay short, so
        each point the front inserts costs a few flips however open the domain is.
        The mesh keeps only the points Basic_aft made; ``info['scaffold']`` is the
        number planted, ``info['scaffold_kept']`` the number that could not be
        removed and stayed as mesh vertices.  A domain narrower than about 8 sizes
        gets none, and so the mesh it gets without.  Only the compiled loop plants
        them (not a Python ``strategy``), never with ``greedy`` or ``max_triangles``.
        False: never.
    partitions : int, optional
        Cut the domain into this many parts of about equal triangle counts and mesh
        them at once (threads, or Dask tasks with ``client``), then stitch them into
        one conforming constrained Delaunay mesh (see :mod:`aftmesh.partition`).
    client : distributed.Client, optional
        Mesh the parts as tasks of this Dask client.
    out : str or Path, optional
        With ``partitions``: write each part as a ``.vtu`` (with global vertex ids) plus
        a ``mesh.pvtu`` into this directory, from the worker that meshed it, and
        return the ``.pvtu`` path instead of a Mesh (read it with
        :func:`aftmesh.read_partitioned`).

    Returns
    -------
    Mesh
        With ``segment_sources``: for each segment, the index of the input edge it
        lies on.  Input edges are numbered as given: for shapely input, polygon by
        polygon (after a collection's overlapping or edge-sharing polygons are
        merged by their union), each polygon's exterior ring then its holes, each
        ring's edges in coordinate order (edge i from coords[i] to coords[i + 1]),
        then the constraint lines' edges in order; for a sequence of polygons the
        same, region by region (an edge shared by two regions takes the first
        one's number); for a dict or ``.poly`` file, the index in ``segments``; for
        an (n, 2) ring, edge i from vertex i to vertex i + 1.  With ``repair=True``
        the numbering is that of the repaired polygons.

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
    arguments = locals()  # the parameters only, at this point
    if partitions is not None or client is not None or out is not None:
        from .partition import generate_partitioned

        k = 1 if partitions is None else partitions
        options = {name: arguments[name] for name in _OPTIONS}
        return generate_partitioned(
            domain, size, partitions=k, client=client, out=out, options=options
        )
    t_start = time.perf_counter()
    opts = _checked(arguments)
    dom = to_domain(
        domain, keep_vertices=not opts.split_boundary, tolerance=opts.tolerance, repair=opts.repair
    )
    if len(dom.vertices) < 3:
        raise InvalidDomainError(f"the domain has {len(dom.vertices)} vertices: nothing to mesh")
    edge_tags = _stages.boundary_tags(dom, opts)
    field = None
    if _common.applies(dom, size, opts):
        # a callable's field is made (and counted) once: for the compiled call, and for
        # the stages if it declines
        if _common.given_field(size):
            field, expected = _stages.size_field(dom, size, opts.gradation, not opts.split_boundary)
            mesh = _common.common_case(dom, field, opts, edge_tags, t_start, expected)
        else:
            mesh = _common.common_case(dom, size, opts, edge_tags, t_start)
        if mesh is not None:
            return mesh
    if field is None:
        field, expected = _stages.size_field(dom, size, opts.gradation, not opts.split_boundary)
    t_boundary = time.perf_counter()
    boundary = _stages.boundary_cdt(dom, field, opts, expected)
    kernel = _stages.prepare_front(boundary, dom, field, opts)
    t_cdt = time.perf_counter()
    _stages.run_front(kernel, opts, boundary.triangle_hint)
    moves = _stages.smooth(kernel, boundary, dom, opts)
    t_aft = time.perf_counter()
    refined = _stages.refine(kernel, boundary, dom, opts)
    t_refine = time.perf_counter()
    timing = _stages.timing(t_start, t_boundary, t_cdt, t_aft, t_refine)
    mesh = _stages.assemble(
        kernel,
        boundary.source,
        boundary.built.n_merged,
        dom,
        field,
        opts,
        moves,
        timing,
        edge_tags,
        refined,
    )
    timing["total"] = time.perf_counter() - t_start
    return mesh


# generate's own defaults of the options, and what check_options makes of them
_KWDEFAULTS: dict = generate.__kwdefaults__ or {}
_DEFAULTS = tuple((k, _KWDEFAULTS[k]) for k in _OPTIONS)
_DEFAULT_OPTIONS = check_options(**dict(_DEFAULTS))


def _checked(arguments: dict) -> Options:
    """check_options of the options among generate's arguments, or the defaults'
    Options (frozen: one serves every call) when each option is the very default
    object, as when it was not given.  Identity, not equality: greedy=0 equals False
    but must still be refused."""
    for k, default in _DEFAULTS:
        if arguments[k] is not default:
            return check_options(**{name: arguments[name] for name in _OPTIONS})
    return _DEFAULT_OPTIONS
