# Converging rows under a constant size, and rows on a size field's plateau, give way
# to one lattice (front.pxi calls in here: Convert_to_frontal_edge_set,
# Compute_new_candidate and Update_internal).
#
# Under one constant size, the rows of triangles that follow a boundary curving round
# the unmeshed region (a disc, the outer circle of an annulus, the ends of a slot)
# shorten layer by layer: a ring of n points at radius r still has n points at r - H.
# Left alone they compress until the converging reach (front.pxi) merges them, and each
# stretch of the rim grows a lattice of its own orientation, so the inside of a disc is
# a patchwork whose seams hold its poor triangles.  Instead, from the second row on
# (an edge between two of Basic_aft's own vertices), R moves to the nearest point of
# one equilateral lattice of the size (a point at the centroid of the region the front
# encloses, its rows along the longest straight side or else along x): the inside is
# one lattice, as in Gmsh's frontal-Delaunay meshes of a disc, and the seam between
# the rows and the lattice is the first row.  R stays a candidate like any other:
# Lemma 3.1's test, Check_visible and the proximity rules judge it as before, and where
# they refuse the lattice point (an earlier R took it, or it is out of sight),
# basic_aft_step judges the point Compute_new_candidate computed before the move, and
# only then takes S.
#
# Why so: over the 256-gon disc, an annulus and a slot, each turned by 0, 3, 11, 29,
# 47 and 71 degrees, the mean radius ratio averaged 0.9927 / 0.9909 / 0.9939 with a
# lattice through input vertex 0 that rows joined once their edges were below 0.97
# of the size and R within 0.4 of the size of a lattice point; from the first row on,
# 0.9949 / 0.9921 / 0.9946; with the centroid, which sits on a disc's or an annulus's
# centre whatever the rim's own vertices are, 0.9964 / 0.9932 / 0.9940; reaching 0.5
# between new vertices, 0.9975 / 0.9940 / 0.9948.  There a refused lattice point sent
# the front to S, and where fronts met last such refusals closed the gap with large
# poor triangles (the annulus's worst turn had 114 triangles at or below 0.9).
# Judging the plain R instead made 0.9976 / 0.9952 / 0.9951, and it let the first
# row's reach fall: 0.35, 0.3, 0.25, 0.2 and none gave 0.9976-0.9979 / 0.9953-0.9956
# / 0.9951-0.9953, the fewest poor triangles without it (disc and annulus none, the
# slot 4-14 against 27-53 at 0.4); and from the second row R always moves (every
# point of the plane is within 0.577 of the size of a lattice point), which did as
# well as a reach of 0.5 or 0.55.  On two sets of 60 and 90 random discs, ellipses,
# slots and rounded boxes, the rule as it stands (against the 0.4 / 0.5 reaches
# without the plain R) took the mean radius ratio from 0.9930 to 0.9932 and from
# 0.9935 to 0.9937, and the triangles at or below 0.9 from 97 to 81 and from 89 to 69
# a domain.
#
# Only rows that come from a curved boundary snap.  Each vertex carries the front's
# curvature: an input vertex the boundary's turn there per unit of length (none at a
# corner, where the rows of the two sides meet in a seam rather than bend), a new
# vertex that of the curve parallel to its edge through it.  Straight boundaries grow
# lattices aligned with themselves, which a common lattice would only disturb: without
# the condition, poly-A, poly-face and poly-double_hex3 lost 0.001-0.007 of mean radius
# ratio, and with it their meshes are unchanged.
#
# The same lattice serves the plateau of a size field that is not one constant: a number
# size whose input has edges shorter than it, so that the cones (sizing.pxi) grade the
# size up from those edges to the number, which then holds over the inside.  There the
# fronts of every stretch of an irregular boundary met in seams of vertices of five and
# seven: inside rw-coast (four sizes or more from the input edges) the triangles had a
# mean radius ratio of 0.985-0.986 and six triangles at 83-84 % of their vertices,
# against Gmsh's 0.994-0.996 and 96-98 % (now 0.9986-1.0000 and 98-100 %; `python -m
# benchmarks.quality rw-coast --bands`).  So on a plateau R moves to the lattice of the
# number when the size at E's middle and at R is the number and both ends of E lie
# LATTICE_PLATEAU_ROWS rows or more from the boundary (a new vertex's row is one more
# than its edge's nearer end; the boundary's vertices are row 0), whatever the
# boundary's curvature: the rows graded up from a short edge have forgotten its
# direction by then, and channels narrower than about twice that many rows never snap,
# so their rows keep following their walls.  On the real-world group of the benchmarks
# the mean radius ratio went from 0.9669 to 0.9674 (rw-coast 0.9754 -> 0.9789,
# rw-poly2tri-funny 0.9766 -> 0.9799, rw-airfoil 0.9953 -> 0.9977, rw-city 0.9863 ->
# 0.9860 the largest loss), on 46 random stars, fractal coastlines and holed coastlines
# from 0.97199 to 0.97362 (39 better, 4 worse by at most 0.0001), and on a 2 x 1
# rectangle with two small polygonal holes turned by 0, 17 and 45 degrees from 0.9913 /
# 0.9910 / 0.9914 to 0.9950 / 0.9950 / 0.9949.  Meshes under one constant size, and
# under a size callable, are unchanged.
#
# Uses: halfedge.pxd; aft.pxd (Aft: vkappa, vrow, lat_on, lat_plateau, lat_o,
# lat_dir, lat_moved, lat_plain, and the size field); triangulation.pxi (_grow).
from halfedge cimport *
from aft cimport Aft
from libc.math cimport sqrt, floor, fabs, isfinite, INFINITY
from libc.stdlib cimport malloc, free
from libc.string cimport memset
from libc.stdint cimport int32_t

# A front turning by more than this (cosine below, about 20 degrees) at a boundary
# vertex is at a corner: no curvature there.
cdef double LATTICE_TURN_COS_MIN = 0.94
# Curvature times the size above this marks a curved row (a radius below 500 sizes):
# a rounding's turn on a straight boundary stays far below.
cdef double LATTICE_CURVED_MIN = 0.002
# A row's curvature grows as 1 / (1 - H kappa) from layer to layer (H the layer's
# height); near its centre of curvature the factor is held at this at most.
cdef double LATTICE_KAPPA_GROWTH_MAX = 2.0
# The lattice's rows run along the longest straight stretch of boundary at least this
# many sizes long, and along x without one.  The rows from a straight side then meet
# the lattice in step: a slot with round ends went from 0.9952 to 0.9959 in mean radius
# ratio over the six turns above (triangles at or below 0.9: 4-14 to 1-5); random
# slots moved by +0.0005, +0.0005 and -0.0002 over three sets, boxes with round ends or
# corners by 0 to +0.0001.  A polygon that stands for a curve has straight input edges
# too: at 2 sizes they turned random ellipses' lattices to one of their edges, for
# -0.0002 to +0.0003; from 8 up, ellipses and discs keep x and their meshes.
cdef double LATTICE_ALIGN_RUN = 8.0
# Joints straighter than this (the sine of the turn, about) continue a straight run:
# the points that split an input edge lie on its line up to rounding (ARCHITECTURE.md's
# rounding rules), and a curve's turns are far above.
cdef double LATTICE_STRAIGHT_SINE = 1e-9
# the height of an equilateral triangle of side 1
cdef double LATTICE_ROW = 0.8660254037844386
# A plateau's lattice takes rows from this many rows off the boundary on: from 2 or
# 3, rows in channels a few sizes wide snapped too and met their walls' own rows in
# two seams instead of one (comb 0.9902 -> 0.9845 at 3, against 0.9894 at 4); from 5,
# less of the gain was kept (the real-world group 0.9672, the random domains 0.97351)
cdef int LATTICE_PLATEAU_ROWS = 4
# Interpolating equal sizes rounds: within this relative distance of the number, the
# size is the plateau's
cdef double LATTICE_PLATEAU_TOLERANCE = 1e-9
cdef enum:
    # lattice_start's mark of a vertex with two front edges into it (or out of it)
    LATTICE_AMBIGUOUS = -2


cdef int _kappa_reserve(Aft* A, int n) noexcept nogil:
    """A.vkappa holds at least n vertices (new entries 0); 0 or ERR_NOMEM."""
    cdef int cap, i
    if n <= A.vkappa_cap:
        return 0
    cap = 2 * n + 64
    if _grow(<void**> &A.vkappa, cap * sizeof(double)):
        return ERR_NOMEM
    for i in range(A.vkappa_cap, cap):
        A.vkappa[i] = 0.0
    A.vkappa_cap = cap
    return 0


cdef inline double _kappa(const Aft* A, int v) noexcept nogil:
    return A.vkappa[v] if 0 <= v < A.vkappa_cap else 0.0


cdef int _row_reserve(Aft* A, int n) noexcept nogil:
    """A.vrow holds at least n vertices (new entries 0); 0 or ERR_NOMEM."""
    cdef int cap, i
    if n <= A.vrow_cap:
        return 0
    cap = 2 * n + 64
    if _grow(<void**> &A.vrow, cap * sizeof(int32_t)):
        return ERR_NOMEM
    for i in range(A.vrow_cap, cap):
        A.vrow[i] = 0
    A.vrow_cap = cap
    return 0


cdef inline int _row(const Aft* A, int v) noexcept nogil:
    return A.vrow[v] if 0 <= v < A.vrow_cap else 0


cdef bint _has_plateau(const Aft* A) noexcept nogil:
    """The size field is a background (not one constant) whose user size is one
    number: every vertex's w is the constant or none, so that wherever the cones stand
    above it the size is that number."""
    cdef int v
    if A.size.nt == 0 or not (A.size.constant > 0.0 and isfinite(A.size.constant)):
        return False
    for v in range(A.size.nv):
        if A.size.w[v] != A.size.constant and isfinite(A.size.w[v]):
            return False
    return True


cdef int lattice_start(Aft* A, Tri* T) noexcept nogil:
    """With the frontal edge set just made: whether rows may snap (New_is_preferred
    in use, and one constant size with a curved stretch of boundary, or a size field
    with a plateau), each front vertex's curvature under one constant size (from the
    front edges into and out of it; none where a vertex has two of either: rings
    touching there) or row 0 on a plateau, and, when rows may snap, the lattice's
    origin and the direction of its rows."""
    cdef int t, k, e, v
    cdef bint curved = False
    cdef int32_t* into
    cdef int32_t* out
    A.lat_plateau = _has_plateau(A)
    A.lat_on = ((A.size.nt == 0 or A.lat_plateau) and A.close_factor > 0.0
                and not A.greedy and T.nv > 0)
    if not A.lat_on:
        return 0
    if A.lat_plateau:
        if _row_reserve(A, T.nv):
            return ERR_NOMEM
        memset(A.vrow, 0, A.vrow_cap * sizeof(int32_t))     # nothing from an earlier run
    else:
        if _kappa_reserve(A, T.nv):
            return ERR_NOMEM
        memset(A.vkappa, 0, A.vkappa_cap * sizeof(double))
    into = <int32_t*> malloc(2 * T.nv * sizeof(int32_t))
    if into == NULL:
        return ERR_NOMEM
    out = into + T.nv
    for v in range(2 * T.nv):
        into[v] = NONE
    for t in range(T.nt):
        if T.tstate[t] != T_UNMESHED:
            continue
        for k in range(3):
            e = 3 * t + k
            if blocking(T, e):
                v = T.tv[nxt(e)]
                into[v] = e if into[v] == NONE else LATTICE_AMBIGUOUS
                v = T.tv[e]
                out[v] = e if out[v] == NONE else LATTICE_AMBIGUOUS
    if not A.lat_plateau:
        for v in range(T.nv):
            if into[v] >= 0 and out[v] >= 0:
                A.vkappa[v] = _turn_per_length(T, into[v], out[v])
                curved = curved or A.vkappa[v] * A.size.constant > LATTICE_CURVED_MIN
    if curved or A.lat_plateau:
        _centroid_origin(A, T, into)
        _align_with_longest_run(A, T, into, out)
    free(into)
    # without a curved stretch of boundary (or a plateau) no row ever snaps: then the
    # loop skips the lattice's bookkeeping altogether (the unit square at size 0.01 ran
    # 0.8 % more instructions than before the lattice without this, 0.3 % with it)
    A.lat_on = curved or A.lat_plateau
    return 0


cdef void _centroid_origin(Aft* A, Tri* T, const int32_t* into) noexcept nogil:
    """A.lat_o: the centroid of the region the front edges enclose (each vertex's edge
    into it, NONE or LATTICE_AMBIGUOUS where lattice_start found none or two: a
    ring's vertex where rings touch then leaves out its edge, which moves the origin a
    little and nothing else), by the shoelace sums about input vertex 0, so that
    coordinates far from 0 do not cancel.  Input vertex 0 where the sums are not
    usable."""
    cdef int v, e
    cdef double ox = T.xy[0], oy = T.xy[1], ax, ay, bx, by, c
    cdef double a2 = 0.0, cx = 0.0, cy = 0.0
    cdef const double* p
    A.lat_o[0] = ox
    A.lat_o[1] = oy
    for v in range(T.nv):
        e = into[v]
        if e < 0:
            continue
        p = P(T, T.tv[e])
        ax = p[0] - ox
        ay = p[1] - oy
        p = P(T, v)
        bx = p[0] - ox
        by = p[1] - oy
        c = ax * by - bx * ay
        a2 += c
        cx += (ax + bx) * c
        cy += (ay + by) * c
    if a2 > 0.0 and isfinite(cx / a2) and isfinite(cy / a2):
        A.lat_o[0] = ox + cx / (3.0 * a2)
        A.lat_o[1] = oy + cy / (3.0 * a2)


cdef inline void _joint(Tri* T, int e, int f, double* u, double* w) noexcept nogil:
    # where edge e ends and edge f starts: u = e's vector, w = f's
    cdef const double* pa = P(T, T.tv[e])
    cdef const double* pb = P(T, T.tv[f])
    cdef const double* pc = P(T, T.tv[nxt(f)])
    u[0] = pb[0] - pa[0]
    u[1] = pb[1] - pa[1]
    w[0] = pc[0] - pb[0]
    w[1] = pc[1] - pb[1]


cdef bint _straight_at(Tri* T, int e, int f) noexcept nogil:
    # edge e ends where edge f starts, and f goes on in e's direction (within
    # LATTICE_STRAIGHT_SINE)
    cdef double u[2]
    cdef double w[2]
    _joint(T, e, f, u, w)
    return (u[0] * w[0] + u[1] * w[1] > 0.0
            and fabs(u[0] * w[1] - u[1] * w[0])
            <= LATTICE_STRAIGHT_SINE * (u[0] * u[0] + u[1] * u[1] + w[0] * w[0] + w[1] * w[1]))


cdef void _align_with_longest_run(Aft* A, Tri* T, const int32_t* into,
                                  const int32_t* out) noexcept nogil:
    """A.lat_dir: the direction of the longest straight run of front edges (a
    straight side, split or not), when it is at least LATTICE_ALIGN_RUN sizes long;
    x otherwise.  Each run is walked once, from its first edge."""
    cdef int v, e, w, n
    cdef double best = 0.0, dx, dy, L
    cdef const double* p0
    cdef const double* p1
    A.lat_dir[0] = 1.0
    A.lat_dir[1] = 0.0
    for v in range(T.nv):
        e = out[v]
        if e < 0:
            continue
        # a run starts at v unless the edge into v goes straight on into e
        if into[v] >= 0 and _straight_at(T, into[v], e):
            continue
        w = T.tv[nxt(e)]
        n = 0
        while n < T.nv and out[w] >= 0 and into[w] >= 0 and _straight_at(T, into[w], out[w]):
            w = T.tv[nxt(out[w])]
            n += 1
        p0 = P(T, v)
        p1 = P(T, w)
        dx = p1[0] - p0[0]
        dy = p1[1] - p0[1]
        L = sqrt(dx * dx + dy * dy)
        if L > best:
            best = L
            A.lat_dir[0] = dx / L
            A.lat_dir[1] = dy / L
    if best < LATTICE_ALIGN_RUN * A.size.constant:
        A.lat_dir[0] = 1.0
        A.lat_dir[1] = 0.0


cdef double _turn_per_length(Tri* T, int e, int f) noexcept nogil:
    """The front's curvature where edge e ends and edge f starts: the turn's sine over
    the mean of the two lengths, or 0 at a corner."""
    cdef double u[2]
    cdef double w[2]
    cdef double lu, lw
    _joint(T, e, f, u, w)
    lu = sqrt(u[0] * u[0] + u[1] * u[1])
    lw = sqrt(w[0] * w[0] + w[1] * w[1])
    if not (lu > 0.0 and lw > 0.0) or u[0] * w[0] + u[1] * w[1] < LATTICE_TURN_COS_MIN * lu * lw:
        return 0.0
    return 2.0 * (u[0] * w[1] - u[1] * w[0]) / (lu * lw * (lu + lw))


cdef int lattice_new_vertex(Aft* A, Tri* T, int v, int a, int b) noexcept nogil:
    """New vertex v, made on front edge a -> b: its curvature, or on a plateau its row
    (see the top)."""
    cdef double kappa, height, L, shrink
    cdef const double* pa
    cdef const double* pb
    cdef const double* pv
    if not A.lat_on:
        return 0
    if A.lat_plateau:
        if _row_reserve(A, v + 1):
            return ERR_NOMEM
        A.vrow[v] = 1 + (_row(A, a) if _row(A, a) < _row(A, b) else _row(A, b))
        return 0
    if _kappa_reserve(A, v + 1):
        return ERR_NOMEM
    kappa = 0.5 * (_kappa(A, a) + _kappa(A, b))
    A.vkappa[v] = 0.0
    if kappa == 0.0:
        return 0
    pa = P(T, a)
    pb = P(T, b)
    pv = P(T, v)
    L = sqrt((pb[0] - pa[0]) * (pb[0] - pa[0]) + (pb[1] - pa[1]) * (pb[1] - pa[1]))
    if not L > 0.0:
        return 0
    height = ((pb[0] - pa[0]) * (pv[1] - pa[1]) - (pb[1] - pa[1]) * (pv[0] - pa[0])) / L
    shrink = 1.0 - height * kappa
    if not shrink >= 1.0 / LATTICE_KAPPA_GROWTH_MAX:
        shrink = 1.0 / LATTICE_KAPPA_GROWTH_MAX
    A.vkappa[v] = kappa / shrink
    return 0


cdef void lattice_snap(Aft* A, Tri* T, int e, double* R, double h) noexcept nogil:
    """Move R to the nearest lattice point when front edge e joins two of Basic_aft's
    vertices, in a curved row under the constant size h, or on a plateau where the
    size h is the plateau's and both lie LATTICE_PLATEAU_ROWS rows or more from the
    boundary; A.lat_moved and A.lat_plain say whether it moved and from where
    (basic_aft_step judges the plain R when the lattice point is refused)."""
    cdef double kappa, x, y, i, j, px, py, d2, row, best = INFINITY, bx = 0.0, by = 0.0
    cdef int di, dj, a = T.tv[e], b = T.tv[nxt(e)]
    if a < A.nv_input or b < A.nv_input:
        return
    if A.lat_plateau:
        if not (h >= A.size.constant * (1.0 - LATTICE_PLATEAU_TOLERANCE)
                and _row(A, a) >= LATTICE_PLATEAU_ROWS and _row(A, b) >= LATTICE_PLATEAU_ROWS):
            return
        h = A.size.constant
    else:
        kappa = 0.5 * (_kappa(A, a) + _kappa(A, b))
        if not kappa * h > LATTICE_CURVED_MIN:
            return
    row = LATTICE_ROW * h
    x = A.lat_dir[0] * (R[0] - A.lat_o[0]) + A.lat_dir[1] * (R[1] - A.lat_o[1])
    y = -A.lat_dir[1] * (R[0] - A.lat_o[0]) + A.lat_dir[0] * (R[1] - A.lat_o[1])
    j = floor(y / row + 0.5)
    i = floor(x / h - 0.5 * j + 0.5)
    # the rounding above can miss the nearest point by one: try the neighbours too
    for dj in range(-1, 2):
        for di in range(-1, 2):
            px = (i + di + 0.5 * (j + dj)) * h
            py = (j + dj) * row
            d2 = (px - x) * (px - x) + (py - y) * (py - y)
            if d2 < best:
                best = d2
                bx = px
                by = py
    A.lat_moved = True
    A.lat_plain[0] = R[0]
    A.lat_plain[1] = R[1]
    R[0] = A.lat_o[0] + A.lat_dir[0] * bx - A.lat_dir[1] * by
    R[1] = A.lat_o[1] + A.lat_dir[1] * bx + A.lat_dir[0] * by
