# generate's common case in one call: one polygon (holes allowed) or a domain without
# holes, region points or regions, meshed at a constant size with the compiled
# subtasks.
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
# Uses: the kernel's def layer (background_field, size_field_count,
# discretize_boundary, Triangulation) and inputs.pxi's checks.

from libc.math cimport nextafter, pow, INFINITY, isfinite, fabs

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


cdef object _common_field(const double[:, ::1] v, const double* box, double res,
                          double constant, double gradation, const double* short,
                          const double[::1] rules, object rounds):
    """make_size_field of a number on these vertices and shortest edges (res: the
    spacing of doubles at the largest coordinate): None for a constant field, False
    where the stages would raise, else the SizeField's arrays (points, user, graded,
    triangles, neighbours, rate, reach)."""
    cdef Py_ssize_t n = v.shape[0], i, nb4 = n + 4
    cdef double c_min = INFINITY, pad, floor, spread, length
    for i in range(n):
        if short[i] < c_min:
            c_min = short[i]
    if c_min >= rules[RULE_CONSTANT_IF_EDGES_ABOVE] * constant:
        return None
    if nb4 > len(rounds):
        return False
    pts_arr = np.empty((nb4, 2), dtype=np.float64)
    u_arr = np.full(nb4, constant)
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
        g[i] = (constant if constant <= length else length) if gradation > 1.0 else length
    tv, nb, finite = background_field(pts_arr, rounds[:nb4], g_arr, spread - 1.0)
    if not finite:
        return False
    return pts_arr, u_arr, g_arr, tv, nb, spread - 1.0, rules[RULE_BOUNDARY_REACH]


cdef double _smallest_size(const double[::1] u, const double[::1] g):
    """SizeField.h_min: the least of min(u, g) over the background's vertices."""
    cdef Py_ssize_t i
    cdef double h = INFINITY, x
    for i in range(u.shape[0]):
        x = u[i] if u[i] <= g[i] else g[i]
        if x < h:
            h = x
    return h


cdef object _inside_exterior(Triangulation tri, const int32_t[::1] piece_edge,
                             const int32_t[::1] edge_source):
    """prepare_front's classification of one valid polygon's pieces (region 0 inside,
    -1 in a hole), without probing: the carve from the hull left only the inner side
    of each exterior-ring segment (source 0), and the inside of a valid polygon is
    connected, so it is the one piece those sides are in; every other piece lies
    inside a hole.  (comp, region of each piece), or None when the sides are in
    more than one piece (then the stages classify by probes)."""
    cdef Tri* T = &tri.T
    cdef int e, s, inside = -1
    comp_arr, _probes, _corners = tri.components()
    cdef int32_t[::1] comp = comp_arr
    for e in range(3 * T.nt):
        s = T.eseg[e]
        if (s < 0 or not T.eflag[e] & E_SEGMENT or T.tstate[e // 3] != T_UNMESHED
                or edge_source[piece_edge[s]] != 0):
            continue
        if inside >= 0 and comp[e // 3] != inside:
            return None
        inside = comp[e // 3]
    if inside < 0:
        return None
    region_arr = np.full(len(_probes), -1, dtype=np.int32)
    region_arr[inside] = 0
    return comp_arr, region_arr


def generate_common(const double[:, ::1] vertices, const int32_t[:, ::1] segments,
                    const int32_t[::1] source, const int32_t[::1] edge_source,
                    bint classify, double constant, double gradation,
                    double area, object rounds, const double[::1] rules, double max_pieces,
                    double progress_limit, int order, long long max_triangles,
                    object min_area, double close_factor, bint swaps, bint greedy,
                    int smooth_rounds, double min_angle):
    """The stages of generate from the size field to the refined mesh, for a number
    size (see the top of pipeline.pxi).  classify: the domain is one valid polygon
    with holes, its rings the sources (edge_source: the source of each input edge),
    the exterior ring source 0.  rounds: _order.round_keys of as many points
    as it holds; max_pieces: the most boundary pieces allowed; progress_limit: the
    triangle hint above which a progress bar may be wanted; min_angle 0: no pass.
    Returns None when the stages must run instead, else (triangulation, source of
    each boundary piece, boundary vertices, merged vertices, the field's arrays or
    None for the constant, expected triangles, smoothing moves, the refine pass's
    counts or None, (t_boundary, t_cdt, t_aft) perf_counter times)."""
    cdef Py_ssize_t n = vertices.shape[0], m = segments.shape[0], i, nv
    cdef double box[4]
    cdef double expected, h_min, covered, share, hint_f, res
    cdef long long hint
    cdef double* short
    if rules.shape[0] != N_RULES:
        raise ValueError(f"rules must hold {N_RULES} values")
    if (m == 0 or n < 3 or source.shape[0] != m or not (constant > 0 and isfinite(constant))
            or not (gradation >= 1.0 and isfinite(gradation))):
        return None
    _check_pslg(vertices, segments)
    box_of(&vertices[0, 0], n, box)
    res = _math_ulp(max(max(fabs(box[0]), fabs(box[1])), max(fabs(box[2]), fabs(box[3]))))
    if not constant >= rules[RULE_MIN_SIZE_ULPS] * res:
        return None
    if not area:
        area = max(box[2] - box[0], 1e-300) * max(box[3] - box[1], 1e-300)
    short = <double*> malloc(n * sizeof(double))
    if short == NULL:
        raise MemoryError()
    try:
        shortest_edges_into(&vertices[0, 0], n, &segments[0, 0], m, short)
        for i in range(n):
            if not isfinite(short[i]):     # a lone point: the stages drop it first
                return None
        field = _common_field(vertices, box, res, constant, gradation, short, rules, rounds)
    finally:
        free(short)
    if field is False:
        return None
    if field is None:
        expected = area / (rules[RULE_EQUILATERAL_AREA] * constant) / constant
        h_min = constant
        args = (constant, _NO_POINTS, _NO_VALUES, _NO_VALUES, _NO_TRIANGLES, _NO_TRIANGLES,
                0.0, 0.0)
    else:
        args = (constant,) + field
        total, covered = size_field_count(*args, rules[RULE_MIN_ESTIMATE_RATE],
                                          rules[RULE_EQUILATERAL_AREA])
        share = area / (covered if covered >= 1e-300 else 1e-300)
        expected = total * (share if share < 1.0 else 1.0) * rules[RULE_ESTIMATE_MARGIN]
        h_min = _smallest_size(field[1], field[2])
    if not expected <= rules[RULE_MAX_TRIANGLES]:
        return None
    t_boundary = perf_counter()
    out = discretize_boundary(*args, vertices, segments, source,
                              <int> rules[RULE_MAX_SAMPLES], max_pieces)
    if out[1] is None:
        return None
    v_out, s_out, e_out = out
    nv = len(v_out)
    hint_f = expected + 4 * nv
    hint = <long long> (hint_f if hint_f < rules[RULE_MAX_TRIANGLE_HINT]
                        else rules[RULE_MAX_TRIANGLE_HINT])
    if hint > progress_limit or nv > len(rounds):
        return None
    if (coordinate_flags(_f64v(v_out), 2 * nv, EXACT_MIN_COORDINATE, EXACT_MAX_COORDINATE)
            or not _pieces_proper(_f64v(v_out), nv, _i32v(s_out), len(s_out))):
        return None
    tri = Triangulation(v_out, <int> min(hint, <long long> rules[RULE_MAX_PREALLOCATED]))
    try:
        _, n_merged, through = tri.insert_pslg(rounds[:nv], s_out, True)
    except (CrossingError, CollinearError):
        return None
    if through:
        return None
    if classify:
        regions = _inside_exterior(tri, e_out, edge_source)
        if regions is None:
            return None
        tri.set_regions(*regions)
    _, n_unmeshed, _ = tri.state_counts()
    if n_unmeshed == 0 or 0 <= max_triangles < n_unmeshed:
        return None
    if min_area is None:
        min_area = rules[RULE_MIN_AREA_FACTOR] * pow(h_min, 2.0)
    tri.set_size_field(*args)
    tri.set_options(order=order, max_triangles=max_triangles, min_area=float(min_area),
                    close_factor=close_factor, swaps=swaps, greedy=greedy)
    t_cdt = perf_counter()
    tri.convert_to_frontal_edge_set()
    tri.run()
    moves = tri.smooth(nv, smooth_rounds) if smooth_rounds else 0
    t_aft = perf_counter()
    done = tri.refine(min_angle, n, True) if min_angle else None
    return (tri, e_out, nv, n_merged, field, expected, moves, done,
            (t_boundary, t_cdt, t_aft))
