# generate's common case in one call: one polygon (holes allowed), polygons whose
# rings meet nowhere, or a dict or .poly domain (with Triangle's hole and region
# points or without), meshed with the compiled subtasks at a number size, at the
# input edges' sizes, or in a size field made before (a callable's, by
# _stages.size_field), its input edges split by the size or kept whole
# (split_boundary=False: then they are the boundary's pieces, and the minimum-angle
# pass splits none of them).
#
# It is the data flow of _stages.py (size field, count, discretization, boundary CDT,
# front, smoothing, minimum-angle pass) with the glue between the kernel calls in C
# instead of Python: the per-call cost of a small domain is mostly that glue.  Every
# rule is the Python stages' own, operation for operation in the same order, so the
# mesh is the one the stages make (tests/test_common_path.py compares the two).  The
# stages keep everything this call does not reproduce: wherever they would retry,
# classify, report progress or raise, this call returns None first and the caller
# runs them instead (from the start: nothing here has side effects).
#
# Uses: the kernel's def layer (background_field, Triangulation) and inputs.pxi's
# checks; one C copy of the size field (sizing.pxi) for the count, the discretization
# (_discretize_on) and the front, which Triangulation.adopt_size_field takes over; past
# the boundary's discretization, the C routines under Triangulation's methods directly
# (_insert_pslg, domain.pxi, front.pxi, smoothing.pxi, refine.pxi), so that they run
# in one nogil stretch.

from libc.math cimport nextafter, pow, INFINITY, isfinite, fabs
from posix.time cimport clock_gettime, timespec, CLOCK_MONOTONIC

# The rules of sizing.py and _stages.py this call applies, by position in `rules`
# (_stages.COMMON_RULES builds the array from the named constants there).
cdef enum:
    RULE_CONSTANT_IF_EDGES_ABOVE = 0
    RULE_BOX_PAD = 1
    RULE_MIN_SIZE_ULPS = 2
    RULE_DEFAULT_GRADATION = 3
    RULE_BOUNDARY_REACH = 4
    RULE_EQUILATERAL_AREA = 5
    RULE_MIN_ESTIMATE_RATE = 6
    RULE_ESTIMATE_MARGIN = 7
    RULE_MAX_TRIANGLES = 8
    RULE_MAX_TRIANGLE_HINT = 9
    RULE_MAX_PREALLOCATED = 10
    RULE_MAX_SAMPLES = 11
    RULE_MIN_AREA_FACTOR = 12
    N_RULES = 13

COMMON_RULE_COUNT = N_RULES

# a constant field's background arrays (none)
_NO_POINTS = np.zeros((0, 2), dtype=np.float64)
_NO_VALUES = np.zeros(0, dtype=np.float64)
_NO_TRIANGLES = np.zeros((0, 3), dtype=np.int32)


cdef inline double _math_ulp(double x) noexcept nogil:
    """math.ulp of a finite x >= 0 below the largest double (refine.pxi's _ulp
    differs at 0 and below the normal range)."""
    return nextafter(x, INFINITY) - x


cdef bint _pieces_proper(const double* xy, Py_ssize_t n, const int32_t* seg,
                         Py_ssize_t m) noexcept nogil:
    """pslg.as_segments accepts the segments: indices in range, no zero length."""
    cdef Py_ssize_t k
    cdef int32_t a, b
    for k in range(m):
        a = seg[2 * k]
        b = seg[2 * k + 1]
        if a < 0 or b < 0 or a >= n or b >= n or a == b:
            return False
        if xy[2 * a] == xy[2 * b] and xy[2 * a + 1] == xy[2 * b + 1]:
            return False
    return True


cdef object _round_keys_of(object round_keys, Py_ssize_t n):
    """round_keys(n) (_order.round_keys: the stages order the same points by the same
    keys), checked to be n keys."""
    keys = round_keys(n)
    if len(keys) != n:
        raise ValueError(f"round_keys({n}) returned {len(keys)} keys")
    return keys


cdef object _common_field(const double[:, ::1] v, const double* box, double res,
                          double constant, double gradation, const double* short,
                          const double[::1] rules, object rounds):
    """make_size_field of a number (0: size=None, the input edges alone) on these
    vertices and shortest edges (res: the spacing of doubles at the largest
    coordinate): None for a constant field, False
    where the stages would raise, else the SizeField's arrays (points, user, graded,
    triangles, neighbours, rate, reach)."""
    cdef Py_ssize_t n = v.shape[0], i, nb4 = n + 4
    cdef double c_min = INFINITY, pad, floor, spread, length
    for i in range(n):
        if short[i] < c_min:
            c_min = short[i]
    if constant > 0 and c_min >= rules[RULE_CONSTANT_IF_EDGES_ABOVE] * constant:
        return None
    cdef double user = constant if constant > 0 else INFINITY
    pts_arr = np.empty((nb4, 2), dtype=np.float64)
    u_arr = np.full(nb4, user)
    g_arr = np.empty(nb4, dtype=np.float64)
    cdef double* pts = _f64v(pts_arr)
    cdef double* g = _f64v(g_arr)
    memcpy(pts, &v[0, 0], 2 * n * sizeof(double))
    pad = box[2] - box[0]
    if box[3] - box[1] > pad:
        pad = box[3] - box[1]
    pad = rules[RULE_BOX_PAD] * pad
    pts[2 * n] = box[0] - pad
    pts[2 * n + 1] = box[1] - pad
    pts[2 * n + 2] = box[2] + pad
    pts[2 * n + 3] = box[1] - pad
    pts[2 * n + 4] = box[2] + pad
    pts[2 * n + 5] = box[3] + pad
    pts[2 * n + 6] = box[0] - pad
    pts[2 * n + 7] = box[3] + pad
    floor = rules[RULE_MIN_SIZE_ULPS] * res
    spread = gradation if gradation > 1.0 else rules[RULE_DEFAULT_GRADATION]
    for i in range(nb4):
        length = (short[i] if short[i] >= floor else floor) if i < n else INFINITY
        g[i] = (user if user <= length else length) if gradation > 1.0 else length
    tv, nb, finite = background_field(pts_arr, _round_keys_of(rounds, nb4), g_arr,
                                      spread - 1.0)
    if not finite:
        return False
    return pts_arr, u_arr, g_arr, tv, nb, spread - 1.0, rules[RULE_BOUNDARY_REACH]


cdef object _edges_field(const double[:, ::1] vertices, const int32_t[:, ::1] segments,
                         const double* box, double res, double constant, double gradation,
                         const double[::1] rules, object rounds, bint split):
    """_common_field from the sizes the input edges ask for at their vertices (the
    shortest edge at each, or with split False the kept-whole sizes), on the vertices
    on a segment: None, False or the field's arrays, as _common_field says."""
    cdef Py_ssize_t n = vertices.shape[0]
    cdef double* short = <double*> malloc(n * sizeof(double))
    try:
        if short == NULL or edge_sizes_into(&vertices[0, 0], n, &segments[0, 0],
                                            segments.shape[0], short, not split):
            raise MemoryError()
        return _common_field(_on_segments(vertices, short), box, res, constant, gradation,
                             short, rules, rounds)
    finally:
        free(short)


cdef object _on_segments(const double[:, ::1] v, double* short):
    """The vertices on a segment, those whose short[i] is finite (v itself when all
    are), with their short values moved to the front of short in the same order: the
    size field's points, as _stages.size_field drops the lone points (a dict's free
    vertices, meshed as they are, ask for no size)."""
    cdef Py_ssize_t n = v.shape[0], i, k = 0
    for i in range(n):
        k += isfinite(short[i])
    if k == n:
        return v
    out_arr = np.empty((k, 2), dtype=np.float64)
    cdef double* out = _f64v(out_arr)
    k = 0
    for i in range(n):
        if isfinite(short[i]):
            out[2 * k] = v[i, 0]
            out[2 * k + 1] = v[i, 1]
            short[k] = short[i]
            k += 1
    return out_arr


cdef double _smallest_size(const double[::1] u, const double[::1] g):
    """SizeField.h_min: the least of min(u, g) over the background's vertices."""
    cdef Py_ssize_t i
    cdef double h = INFINITY, x
    for i in range(u.shape[0]):
        x = u[i] if u[i] <= g[i] else g[i]
        if x < h:
            h = x
    return h


cdef int _inside_exterior(Tri* T, const int32_t* piece_edge,
                          const int32_t* edge_source) noexcept nogil:
    """prepare_front's classification of one valid polygon's pieces (region 0 inside,
    -1 in a hole), without probing: the carve from the hull left only the inner side
    of each exterior-ring segment (source 0), and the inside of a valid polygon is
    connected, so it is the one piece those sides are in; every other piece lies
    inside a hole.  Returns 1 when it set the regions, 0 when the sides are in more
    than one piece (then the stages classify by probes), or an error."""
    cdef int e, s, t, nc, inside = -1, res = 1
    cdef int n = T.nt if T.nt > 0 else 1
    cdef int32_t* comp = <int32_t*> malloc(n * sizeof(int32_t))
    cdef int32_t* best = <int32_t*> malloc(n * sizeof(int32_t))
    cdef int32_t* region = NULL
    if comp == NULL or best == NULL:
        free(comp)
        free(best)
        return ERR_NOMEM
    for t in range(T.nt):
        comp[t] = -1
    nc = domain_components(T, comp, best)
    if nc < 0:
        res = nc
    for e in range(3 * T.nt if res > 0 else 0):
        s = T.eseg[e]
        if (s < 0 or not T.eflag[e] & E_SEGMENT or T.tstate[e // 3] != T_UNMESHED
                or edge_source[piece_edge[s]] != 0):
            continue
        if inside >= 0 and comp[e // 3] != inside:
            res = 0
            break
        inside = comp[e // 3]
    if res > 0 and inside < 0:
        res = 0
    if res > 0:
        region = <int32_t*> malloc(nc * sizeof(int32_t))
        if region == NULL:
            res = ERR_NOMEM
        else:
            for t in range(nc):
                region[t] = -1
            region[inside] = 0
            set_regions(T, comp, T.nt, region)
    free(region)
    free(comp)
    free(best)
    return res


cdef void _check_ring_polygon(const int32_t[::1] edge_source,
                              const int32_t[::1] ring_polygon, bint classify) except *:
    """generate_common's ring_polygon names a polygon for every source of edge_source."""
    cdef Py_ssize_t i, k = ring_polygon.shape[0]
    if not classify:
        raise ValueError("ring_polygon classifies pieces: classify must be set with it")
    for i in range(edge_source.shape[0]):
        if not 0 <= edge_source[i] < k:
            raise ValueError(f"edge_source[{i}] = {edge_source[i]} names no ring of "
                             f"ring_polygon (length {k})")


cdef bint _seed_points_usable(object holes, object seeds, object seed_ids) except -1:
    """generate_common's hole and region points are (h, 2) and (r, 2) with r ids (a
    ValueError if not) and every coordinate is in the exact predicates' range (else
    the stages check them, with their messages)."""
    cdef const double[:, ::1] hv = np.zeros((0, 2)) if holes is None else holes
    cdef const double[:, ::1] sv = np.zeros((0, 2)) if seeds is None else seeds
    cdef const int32_t[::1] iv = np.zeros(0, dtype=np.int32) if seed_ids is None else seed_ids
    if hv.shape[1] != 2 or sv.shape[1] != 2 or iv.shape[0] != sv.shape[0]:
        raise ValueError("holes and seeds must be (h, 2) and (r, 2), seed_ids (r,)")
    return not (
        coordinate_flags(&hv[0, 0] if hv.shape[0] else NULL, 2 * hv.shape[0],
                         EXACT_MIN_COORDINATE, EXACT_MAX_COORDINATE)
        or coordinate_flags(&sv[0, 0] if sv.shape[0] else NULL, 2 * sv.shape[0],
                            EXACT_MIN_COORDINATE, EXACT_MAX_COORDINATE))


cdef double _clock() noexcept nogil:
    """time.perf_counter() (CLOCK_MONOTONIC on Linux, in seconds), without the GIL."""
    cdef timespec ts
    clock_gettime(CLOCK_MONOTONIC, &ts)
    return <double> (<int64_t> ts.tv_sec * 1000000000 + ts.tv_nsec) / 1e9


# How _mesh_pieces ended
cdef enum:
    PIECES_RAN = 0            # to the end, or to the kernel error in Pieces.res
    PIECES_DECLINED = 1       # the stages must run instead
    PIECES_INSERT_FAILED = 2  # insert_pslg's error: a crossing or collinear one declines
    PIECES_BUILT = 3          # the classified CDT, the front still to run


cdef struct Pieces:
    # in: the boundary pieces and what to run on them
    const int64_t* rounds
    const int32_t* seg
    int m
    const int32_t* piece_edge   # NULL: no classification (no holes)
    const int32_t* edge_source
    const int32_t* ring_polygon  # not NULL: the pieces nest (domain.pxi's nested_regions)
    const double* holes         # Triangle's hole points (2 per hole)
    int n_holes
    const double* seeds         # Triangle's region points (2 each) and their ids
    const int32_t* seed_ids
    int n_seeds
    long long max_triangles
    int first_movable
    int n_corner                # input vertices: the split points after them slide
    int smooth_rounds
    bint refining
    # out
    int res                     # the first kernel error, or >= 0
    int n_merged, through, failed, moves
    double t_cdt, t_aft


cdef int _mesh_pieces(Tri* T, Aft* A, Refine* R, int32_t* merged, Pieces* P) noexcept nogil:
    """The stages from the boundary CDT to the refined mesh without the GIL, in one
    stretch: a thread meshing small domains then takes the GIL back once per domain,
    not once per stage (each time it may have to wait for another thread's Python
    work).  The checks between the stages are the stages' own (see generate_common)."""
    cdef int outcome = _pieces_cdt(T, merged, P)
    return _pieces_meshed(T, A, R, P) if outcome == PIECES_BUILT else outcome


cdef int _pieces_cdt(Tri* T, int32_t* merged, Pieces* P) noexcept nogil:
    """_mesh_pieces to the classified CDT (Triangle's hole and region points, the
    nesting or inside of the rings): PIECES_BUILT, or how it ended."""
    P.res = _insert_pslg(T, P.rounds, P.seg, P.m, True, merged, &P.n_merged, &P.through,
                         &P.failed)
    if P.res < 0:
        return PIECES_INSERT_FAILED
    if P.through:
        return PIECES_DECLINED
    if P.n_holes or P.n_seeds:
        P.res = _carve_and_seed(T, P)
        if P.res <= 0:
            return PIECES_DECLINED if P.res == 0 else PIECES_RAN
    if P.ring_polygon != NULL:
        P.res = nested_regions(T, P.piece_edge, P.edge_source, P.ring_polygon)
        if P.res <= 0:
            return PIECES_DECLINED if P.res == 0 else PIECES_RAN
    elif P.piece_edge != NULL:
        P.res = _inside_exterior(T, P.piece_edge, P.edge_source)
        if P.res <= 0:
            return PIECES_DECLINED if P.res == 0 else PIECES_RAN
    return PIECES_BUILT


cdef int _pieces_meshed(Tri* T, Aft* A, Refine* R, Pieces* P) noexcept nogil:
    """_mesh_pieces from the classified CDT on: the stages' checks of its triangles,
    Basic_aft, smoothing, the minimum-angle pass."""
    cdef int i, n_unmeshed = 0
    for i in range(T.nt):
        n_unmeshed += T.tstate[i] == T_UNMESHED
    if n_unmeshed == 0 or 0 <= P.max_triangles < n_unmeshed:
        return PIECES_DECLINED
    P.t_cdt = _clock()
    P.res = convert_to_frontal_edge_set(A, T)
    if P.res >= 0:
        P.res = basic_aft_loop(A, T)
    if P.res >= 0 and P.smooth_rounds:
        P.res = smooth(A, T, P.first_movable, P.smooth_rounds, True, P.n_corner)
        P.moves = P.res
    P.t_aft = _clock()
    if P.res >= 0 and P.refining:
        P.res = refine_settled(R, A, T, P.first_movable, P.n_corner >= 0, P.smooth_rounds)
    return PIECES_RAN


cdef int _carve_and_seed(Tri* T, const Pieces* P) noexcept nogil:
    """pslg.build_cdt's hole and region points, in its order: each point checked
    inside the domain and off the segments (seed_state), the holes carved, the
    regions flooded.  Returns 1, 0 where a point fails its check (the stages then
    raise, naming it), or an error."""
    cdef int i, state, res
    for i in range(P.n_holes + P.n_seeds):
        state = seed_state(T, &P.holes[2 * i] if i < P.n_holes
                           else &P.seeds[2 * (i - P.n_holes)])
        if state < 0:
            return state
        if state != T_UNMESHED:
            return 0
    if P.n_holes:
        res = carve_domain(T, P.holes, P.n_holes, False)
        if res < 0:
            return res
    if P.n_seeds:
        res = assign_regions(T, P.seeds, P.seed_ids, P.n_seeds)
        if res < 0:
            return res
    return 1


cdef object _mesh_from_pieces(Triangulation tri, const int64_t[::1] rounds,
                              const int32_t[:, ::1] seg, object piece_edge,
                              const int32_t[::1] edge_source, object ring_polygon,
                              object holes, object seeds, object seed_ids,
                              long long max_triangles,
                              int smooth_rounds, bint slide, double min_angle,
                              bint split, int n_corners, object classify_cb=None):
    """_mesh_pieces on tri (its size field and options set; split: the minimum-angle
    pass may split input segments), with the def layer's error handling: None where
    the stages must run, else (merged vertices, smoothing moves, the refine pass's
    counts or None, t_cdt, t_aft).  classify_cb (not None: pieces classified by
    probes) gives the region of each piece of the CDT from its probes and corners
    (Triangulation.components), as _stages.prepare_front does, between the CDT and the
    front."""
    cdef Pieces P
    cdef Refine R
    cdef int outcome, nv = tri.T.nv
    cdef const int32_t[::1] pe
    cdef const int32_t[::1] rp
    cdef const double[:, ::1] hv
    cdef const double[:, ::1] sv
    cdef const int32_t[::1] iv
    memset(&P, 0, sizeof(Pieces))
    P.m = seg.shape[0]
    P.rounds = &rounds[0] if nv else NULL
    P.seg = &seg[0, 0] if P.m else NULL
    if piece_edge is not None:
        pe = piece_edge
        P.piece_edge = &pe[0]
        P.edge_source = &edge_source[0]
        if ring_polygon is not None:
            rp = ring_polygon
            P.ring_polygon = &rp[0]
    if holes is not None:
        hv = holes
        P.n_holes = hv.shape[0]
        P.holes = &hv[0, 0] if P.n_holes else NULL
    if seeds is not None:
        sv = seeds
        iv = seed_ids
        P.n_seeds = sv.shape[0]
        P.seeds = &sv[0, 0] if P.n_seeds else NULL
        P.seed_ids = &iv[0] if P.n_seeds else NULL
    P.max_triangles = max_triangles
    P.first_movable = nv
    P.n_corner = n_corners if slide else -1
    P.smooth_rounds = smooth_rounds
    P.refining = min_angle != 0
    memset(&R, 0, sizeof(Refine))
    if P.refining:
        _refine_setup(&R, min_angle, n_corners, split)
    merged_arr = np.empty(nv, dtype=np.int32)
    cdef int32_t* merged = _i32v(merged_arr)
    tri.A.progress = NULL
    tri._note_thread()
    try:
        if classify_cb is None:
            with nogil:
                outcome = _mesh_pieces(&tri.T, &tri.A, &R, merged, &P)
        else:
            with nogil:
                outcome = _pieces_cdt(&tri.T, merged, &P)
            if outcome == PIECES_BUILT:
                comp, probes, corners = tri.components()
                tri.set_regions(comp, classify_cb(probes, corners))
                with nogil:
                    outcome = _pieces_meshed(&tri.T, &tri.A, &R, &P)
    finally:
        refine_free(&R)
    if outcome == PIECES_INSERT_FAILED:
        try:
            _raise_for(&tri.T, P.res)
        except (CrossingError, CollinearError):
            return None
    if outcome == PIECES_DECLINED:
        return None
    _reraise_pending(&tri.A)
    _raise_for(&tri.T, P.res)
    if DEBUG:
        problems = tri.validate()
        if problems:
            raise KernelError("after Basic_aft and refine: " + "; ".join(problems[:5]))
    done = _refine_counts(&R) if P.refining else None
    return P.n_merged, P.moves, done, P.t_cdt, P.t_aft


def generate_common(const double[:, ::1] vertices, const int32_t[:, ::1] segments,
                    const int32_t[::1] source, const int32_t[::1] edge_source,
                    bint classify, object ring_polygon, object holes, object seeds,
                    object seed_ids,
                    double constant, double gradation,
                    double area, object rounds, const double[::1] rules, double max_pieces,
                    double progress_limit, int order, long long max_triangles,
                    object min_area, double close_factor, bint swaps, bint greedy,
                    int smooth_rounds, bint slide, double min_angle, bint scaffold,
                    bint split=True, object given=None, double given_expected=-1.0,
                    object classify_cb=None):
    """The stages of generate from the size field to the refined mesh, for a number
    size, `constant` (0: size=None, the input edges' lengths alone; see the top of
    pipeline.pxi).  classify: the domain is one valid polygon with holes, its rings
    the sources (edge_source: the source of each input edge), the exterior ring
    source 0; or, with ring_polygon (an int32 array: the polygon of each source
    ring), a valid multipolygon whose rings meet nowhere, its pieces classified by how
    they nest (domain.pxi's nested_regions).  holes, seeds and seed_ids: Triangle's
    hole points and region points with their ids (float64 (h, 2), (r, 2) and int32
    (r,) arrays, or None for none), as pslg.build_cdt applies them.  rounds:
    _order.round_keys, called for the BRIO round keys of the background's and the
    boundary's points; max_pieces: the most boundary pieces allowed; progress_limit:
    the triangle hint above which a progress bar may be wanted; slide: smoothing
    slides the boundary's split points along their input edges; min_angle 0: no
    pass; split: the input edges are cut by the size (split_boundary), else kept
    whole; given: a size field _stages.size_field made (a callable's, or a SizeField
    the caller passed), as its kernel_args()[1:], used as it is (constant: its
    constant), else None; given_expected: the triangles it asks for as
    _stages.size_field counted them (< 0: count here).  classify_cb: for polygons
    whose pieces neither the exterior ring nor their nesting classifies (a list of
    regions, constraint lines and points), the region of each piece from its probes
    and corners (regions.classify_pieces on the polygons), called between the CDT and
    the front; classify is then off.
    Returns None when the stages must run instead, else (triangulation, source of
    each boundary piece, boundary vertices, merged vertices, the field's arrays or
    None for the constant, expected triangles, smoothing moves, the refine pass's
    counts or None, (t_boundary, t_cdt, t_aft) perf_counter times)."""
    cdef Py_ssize_t n = vertices.shape[0], m = segments.shape[0]
    cdef double box[4]
    cdef double res
    cdef SizeField S
    if rules.shape[0] != N_RULES:
        raise ValueError(f"rules must hold {N_RULES} values")
    if (m == 0 or n < 3 or source.shape[0] != m or not (constant >= 0 and isfinite(constant))
            or not (gradation >= 1.0 and isfinite(gradation))):
        return None
    _check_pslg(vertices, segments)
    if ring_polygon is not None:
        _check_ring_polygon(edge_source, ring_polygon, classify)
    seeded = holes is not None or seeds is not None
    if seeded and not _seed_points_usable(holes, seeds, seed_ids):
        return None
    box_of(&vertices[0, 0], n, box)
    res = _math_ulp(max(max(fabs(box[0]), fabs(box[1])), max(fabs(box[2]), fabs(box[3]))))
    if given is None and constant and not constant >= rules[RULE_MIN_SIZE_ULPS] * res:
        return None
    if not area:
        area = max(box[2] - box[0], 1e-300) * max(box[3] - box[1], 1e-300)
    if given is not None:
        field = None if len(given[3]) == 0 else given
    else:
        field = _edges_field(vertices, segments, box, res, constant, gradation, rules,
                             rounds, split)
        if field is False:
            return None
    # one copy of the field serves the count, the discretization and the front, each
    # walking from the first background triangle as a fresh copy would
    memset(&S, 0, sizeof(SizeField))
    try:
        return _generate_on(&S, field, vertices, segments, source, edge_source, classify,
                            ring_polygon, holes, seeds, seed_ids, constant, area, rules,
                            rounds, max_pieces, progress_limit, order, max_triangles,
                            min_area, close_factor, swaps, greedy, smooth_rounds, slide,
                            min_angle, scaffold, split, given_expected, n, classify_cb)
    finally:
        size_field_free(&S)


cdef object _generate_on(SizeField* S, object field, const double[:, ::1] vertices,
                         const int32_t[:, ::1] segments, const int32_t[::1] source,
                         const int32_t[::1] edge_source, bint classify,
                         object ring_polygon, object holes, object seeds,
                         object seed_ids,
                         double constant,
                         double area, const double[::1] rules, object rounds,
                         double max_pieces, double progress_limit, int order,
                         long long max_triangles, object min_area, double close_factor,
                         bint swaps, bint greedy, int smooth_rounds, bint slide,
                         double min_angle, bint scaffold, bint split,
                         double expected_in, Py_ssize_t n, object classify_cb):
    """generate_common from its size field on (field: _common_field's arrays, or None
    for the constant), S the kernel's copy of it, which the triangulation takes;
    expected_in: the count of a given field, made already (< 0: none)."""
    cdef double expected, h_min, covered, share, hint_f, total
    cdef long long hint
    cdef Py_ssize_t nv
    if field is None:
        expected = area / (rules[RULE_EQUILATERAL_AREA] * constant) / constant
        h_min = constant
        _field_of(S, constant, _NO_POINTS, _NO_VALUES, _NO_VALUES, _NO_TRIANGLES,
                  _NO_TRIANGLES, 0.0, 0.0)
    else:
        _field_of(S, constant, field[0], field[1], field[2], field[3], field[4], field[5],
                  field[6])
        if expected_in >= 0:
            expected = expected_in
        else:
            total = count_triangles_asked(S, rules[RULE_MIN_ESTIMATE_RATE],
                                          rules[RULE_EQUILATERAL_AREA], &covered)
            share = area / (covered if covered >= 1e-300 else 1e-300)
            expected = total * (share if share < 1.0 else 1.0) * rules[RULE_ESTIMATE_MARGIN]
        h_min = _smallest_size(field[1], field[2])
    if not expected <= rules[RULE_MAX_TRIANGLES]:
        return None
    t_boundary = perf_counter()
    if split:
        S.hint = 0
        out = _discretize_on(S, vertices, segments, source, <int> rules[RULE_MAX_SAMPLES],
                             max_pieces)
        if out[1] is None:
            return None
        v_out, s_out, e_out = out
    else:   # the input edges are the boundary's pieces (_stages.boundary_cdt)
        v_out, s_out, e_out = np.asarray(vertices), np.asarray(segments), np.asarray(source)
    nv = len(v_out)
    hint_f = expected + 4 * nv
    hint = <long long> (hint_f if hint_f < rules[RULE_MAX_TRIANGLE_HINT]
                        else rules[RULE_MAX_TRIANGLE_HINT])
    if hint > progress_limit:
        return None
    if (coordinate_flags(_f64v(v_out), 2 * nv, EXACT_MIN_COORDINATE, EXACT_MAX_COORDINATE)
            or not _pieces_proper(_f64v(v_out), nv, _i32v(s_out), len(s_out))):
        return None
    if min_area is None:
        min_area = rules[RULE_MIN_AREA_FACTOR] * pow(h_min, 2.0)
    cdef Triangulation tri = Triangulation(
        v_out, <int> min(hint, <long long> rules[RULE_MAX_PREALLOCATED]))
    tri.adopt_size_field(S)
    tri.set_options(order=order, max_triangles=max_triangles, min_area=float(min_area),
                    close_factor=close_factor, swaps=swaps, greedy=greedy,
                    scaffold=scaffold)
    out = _mesh_from_pieces(tri, _round_keys_of(rounds, nv), s_out,
                            e_out if classify else None, edge_source, ring_polygon,
                            holes, seeds, seed_ids, max_triangles, smooth_rounds, slide,
                            min_angle, split, n, classify_cb)
    if out is None:
        return None
    n_merged, moves, done, t_cdt, t_aft = out
    return (tri, e_out, nv, n_merged, field, expected, moves, done,
            (t_boundary, t_cdt, t_aft))
