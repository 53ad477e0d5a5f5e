# Basic_aft (Figure 5 of the paper) on the constrained Delaunay triangulation (§3).
#
# One triangulation covers the whole domain.  Each triangle is T_UNMESHED or T_MESHED;
# the frontal edge set C is implicit: a half-edge is a front edge exactly when it is
# constrained (blocking(): an input segment, or the boundary between the two states)
# and its own triangle is unmeshed.  So the unmeshed triangles are cd(S(E)) for every
# component at once, and
#   * Compute_existing_candidate is the apex of the unmeshed triangle on E;
#   * Update_boundary's "if -F in C delete -F else insert F" (Figure 6, all four cases:
#     toggles, the closing three-edge case, a split component, a merged hole) happens by
#     itself when T(E, S) changes state: an edge of it that was a front edge stops being
#     one, an unconstrained one becomes a front edge seen from the other side;
#   * Update_internal inserts R into cd(S(E)) and makes sure F and G are edges.
# The queue only orders the work (Get_next_edge); it is not the definition of C, so
# stale entries are simply skipped (lazy deletion).
#
# Uses: halfedge.pxd; aft.pxd (Aft, QueueItem); sizing.pxi (size_at); lattice.pxi;
# predicates.pxi; triangulation.pxi (find_edge, insert_vertex_at, add_vertex,
# legalize_meshed, reserve_stack, _grow); cdt.pxi (insert_segment); valence.pxi
# (_angle_at).
from halfedge cimport *
from aft cimport Aft, QueueItem
from libc.math cimport sqrt, floor, log2, fabs
from libc.stdlib cimport malloc, free
from libc.string cimport memset, memcpy
from libc.stdint cimport uint64_t

# Tuning constants of the compiled loop (each with the reason for its value).
# Get_next_edge compares lengths in classes of 2**(1/8) (about 9 %): the key is
# floor(4 log2(|E|^2)), i.e. eighths of an octave of |E| (_quarter_octaves).
cdef enum:
    # steps between two looks at Python's signal handlers and the progress callable:
    # rare enough to cost nothing, frequent enough for Ctrl-C to answer within ~10 ms
    SIGNAL_CHECK_INTERVAL = 8192
    # is_crowded looks at no more triangles than this: the cavity within close_factor
    # * h of R holds a handful of near-equilateral triangles; more means a crowd anyway
    CROWD_SEARCH_MAX = 32
    QUEUE_INITIAL_CAP = 1024    # queued items, grown by doubling
    # Length classes are floor(4 log2 |E|^2), within +-4296 for any positive double
    # square; these bounds hold them with room, and -inf / +inf (a square that
    # underflows to 0 or overflows) go to the classes below and above.
    QUEUE_CLASS_BOUND = 4300
    QUEUE_CLASSES = 2 * QUEUE_CLASS_BOUND + 3
    LR_INITIAL_CAP = 64         # Check_visible's crossed-edge lists, grown by doubling
# New_is_preferred's default: take S when |S - R| < DEFAULT_CLOSE_FACTOR * h
cdef double DEFAULT_CLOSE_FACTOR = 0.5
# is_crowded refuses R closer than EDGE_PROXIMITY * close_factor * h to a constrained
# edge it faces: where two fronts are closer than R's height (about 0.87 h) plus that,
# about 1.2 h, R would leave a gap of a fraction of h that only slivers fill, so the
# front connects across instead.
# Raising it from 0.5 raised the real-world group's mean radius ratio (0.85 by most),
# but from 0.7 on a single triangle of the squares fell below 40 degrees.
cdef double EDGE_PROXIMITY = 0.65

from cpython.ref cimport PyObject

cdef extern from "Python.h":
    # declared here without Cython's "except -1" so that the compiled loop can turn a
    # pending signal into a status code instead of an exception inside a nogil routine
    int PyErr_CheckSignals()
    void PyErr_Clear()
    void PyErr_Fetch(PyObject** ptype, PyObject** pvalue, PyObject** ptraceback)
    void PyErr_Restore(PyObject* ptype, PyObject* pvalue, PyObject* ptraceback)

cdef int aft_init(Aft* A) noexcept nogil:
    memset(A, 0, sizeof(Aft))
    A.lr_cap = LR_INITIAL_CAP
    A.left = <int32_t*> malloc(A.lr_cap * sizeof(int32_t))
    A.right = <int32_t*> malloc(A.lr_cap * sizeof(int32_t))
    A.size.constant = 1.0
    A.max_triangles = -1
    A.close_factor = DEFAULT_CLOSE_FACTOR
    A.swaps = True
    A.signals_here = True
    A.scaffold_on = False
    if A.left == NULL or A.right == NULL:
        return ERR_NOMEM
    queue_clear(A)
    return 0


cdef void aft_free(Aft* A) noexcept nogil:
    free(A.items)
    free(A.first)
    free(A.head)
    free(A.tail)
    free(A.left)
    free(A.right)
    free(A.scaffold_alive)
    free(A.vkappa)
    free(A.vrow)
    size_field_free(&A.size)
    memset(A, 0, sizeof(Aft))


# ---------------------------------------------------------------- the queue
#
# Get_next_edge takes the front edge of the smallest length class, the oldest within a
# class, after the initial front (see _queue_initial_first); or the longest class
# first, or plain first in first out (A.order).  Classes
# are small integers, so the queue is one first-in first-out list per class: pushing
# and popping cost O(1), where a binary heap's sifting cost a tenth of the run time.

cdef int _queue_alloc(Aft* A) noexcept nogil:
    """The queue's storage, made at its first use: most triangulations (a size
    field's background, aftmesh.cdt) never run the front.  0 or ERR_NOMEM."""
    A.items = <QueueItem*> malloc(QUEUE_INITIAL_CAP * sizeof(QueueItem))
    A.head = <int32_t*> malloc(QUEUE_CLASSES * sizeof(int32_t))
    A.tail = <int32_t*> malloc(QUEUE_CLASSES * sizeof(int32_t))
    if A.items == NULL or A.head == NULL or A.tail == NULL:
        return ERR_NOMEM
    A.items_cap = QUEUE_INITIAL_CAP
    return 0


cdef void _queue_cover(Aft* A, int c) noexcept nogil:
    """Widen the classes in use, [used_low, used_high], to hold c; the classes it
    adds start empty.  Only that range is ever read, so a run whose lengths span a
    few octaves sets a few dozen classes, not all QUEUE_CLASSES of them."""
    cdef int lo = c, hi = c
    if A.used_low <= A.used_high:       # a range in use: add only what is new
        if c < A.used_low:
            hi = A.used_low - 1
        else:
            lo = A.used_high + 1
    memset(&A.head[lo], 0xFF, (hi - lo + 1) * sizeof(int32_t))     # -1: empty
    memset(&A.tail[lo], 0xFF, (hi - lo + 1) * sizeof(int32_t))
    if c < A.used_low:
        A.used_low = c
    if c > A.used_high:
        A.used_high = c


cdef void queue_clear(Aft* A) noexcept nogil:
    """Empty the queue: no class is in use any more."""
    A.used_low = QUEUE_CLASSES
    A.used_high = -1
    A.queue_n = 0
    A.items_n = 0
    A.free_item = -1
    A.low_class = QUEUE_CLASSES
    A.first_n = 0
    A.first_pos = 0


# 2**(1/4), 2**(1/2), 2**(3/4): the mantissa's class boundaries (_quarter_octaves)
cdef double QUARTER_OCTAVE_1 = 1.189207115002721
cdef double QUARTER_OCTAVE_2 = 1.4142135623730951
cdef double QUARTER_OCTAVE_3 = 1.681792830507429
# a mantissa this close to a class boundary (or to 1 or 2) is classed by log2 itself:
# there its rounding, not the exact value, decides the class (a square one ulp below
# 2**-4 lands in 2**-4's class, one ulp below 2**-2 in the class below), and far
# beyond log2's error (an ulp of the result) everywhere else the two agree
cdef double QUARTER_OCTAVE_MARGIN = 1e-9


cdef inline double _quarter_octaves(double s) noexcept nogil:
    # floor(4 log2 s), as floor(4.0 * log2(s)) gives it, from the bits of s where no
    # rounding can matter: a normal double is m 2**e with m in [1, 2), and the class
    # of m is its place among the 2**(k/4).  Every queued edge needs one, and this
    # costs far less than a log2 call.
    cdef uint64_t bits
    cdef int ex
    cdef double m
    memcpy(&bits, &s, sizeof(double))
    ex = <int> ((bits >> 52) & 0x7ff)
    bits = (bits & 0x000fffffffffffffULL) | 0x3ff0000000000000ULL
    memcpy(&m, &bits, sizeof(double))
    if (ex == 0 or ex == 0x7ff or s < 0.0
            or m < 1.0 + QUARTER_OCTAVE_MARGIN or m > 2.0 - QUARTER_OCTAVE_MARGIN
            or fabs(m - QUARTER_OCTAVE_1) < QUARTER_OCTAVE_MARGIN
            or fabs(m - QUARTER_OCTAVE_2) < QUARTER_OCTAVE_MARGIN
            or fabs(m - QUARTER_OCTAVE_3) < QUARTER_OCTAVE_MARGIN):
        return floor(4.0 * log2(s))
    return <double> (4 * (ex - 1023) + (m > QUARTER_OCTAVE_1) + (m > QUARTER_OCTAVE_2)
                     + (m > QUARTER_OCTAVE_3))


cdef inline int _length_class(Aft* A, double dx, double dy) noexcept nogil:
    # Lengths are compared in classes about 9 % wide (eighths of an octave of the
    # length), oldest first within a class.  With exact lengths, edges a
    # rounding error shorter than the rest would win every time, and one lattice
    # would sweep the whole domain before the other boundaries' layers started;
    # classes make the fronts of equal size advance together, layer by layer.
    cdef double key
    if A.order == ORDER_SHORTEST:
        key = _quarter_octaves(dx * dx + dy * dy)
    elif A.order == ORDER_LONGEST:
        key = -_quarter_octaves(dx * dx + dy * dy)
    else:
        return QUEUE_CLASS_BOUND + 1
    if key < -QUEUE_CLASS_BOUND:
        return 0
    if not key <= QUEUE_CLASS_BOUND:
        return 2 * QUEUE_CLASS_BOUND + 2
    return <int> key + QUEUE_CLASS_BOUND + 1


cdef int queue_push(Aft* A, Tri* T, int e) noexcept nogil:
    """Queue front half-edge e at the end of its length class; 0 or ERR_NOMEM."""
    cdef int i, c
    cdef int org = T.tv[e], dst = T.tv[nxt(e)]
    if A.head == NULL and _queue_alloc(A):
        return ERR_NOMEM
    if A.free_item >= 0:
        i = A.free_item
        A.free_item = A.items[i].next
    else:
        if A.items_n == A.items_cap:
            if _grow(<void**> &A.items, 2 * A.items_cap * sizeof(QueueItem)):
                return ERR_NOMEM
            A.items_cap *= 2
        i = A.items_n
        A.items_n += 1
    A.items[i].he = e
    A.items[i].org = org
    A.items[i].dst = dst
    A.items[i].next = -1
    c = _length_class(A, T.xy[2 * dst] - T.xy[2 * org], T.xy[2 * dst + 1] - T.xy[2 * org + 1])
    if c < A.used_low or c > A.used_high:
        _queue_cover(A, c)
    if A.tail[c] >= 0:
        A.items[A.tail[c]].next = i
    else:
        A.head[c] = i
    A.tail[c] = i
    if c < A.low_class:
        A.low_class = c
    A.queue_n += 1
    return 0


cdef void queue_pop(Aft* A, QueueItem* out) noexcept nogil:
    """Take the next edge of the initial front while there is one (see
    _queue_initial_first), else the oldest item of the lowest class holding one
    (A.queue_n > 0)."""
    cdef int c = A.low_class, i
    if A.first_pos < A.first_n:
        out[0] = A.first[A.first_pos]
        A.first_pos += 1
        A.queue_n -= 1
        return
    while A.head[c] < 0:
        c += 1
    A.low_class = c
    i = A.head[c]
    out[0] = A.items[i]
    A.head[c] = A.items[i].next
    if A.head[c] < 0:
        A.tail[c] = -1
    A.items[i].next = A.free_item
    A.free_item = i
    A.queue_n -= 1


cdef inline bint is_front(Tri* T, int e) noexcept nogil:
    return T.tstate[e // 3] == T_UNMESHED and blocking(T, e)


# ---------------------------------------------------------------- the subtasks

cdef inline double _tri_area(Tri* T, int t) noexcept nogil:
    cdef double* a = P(T, T.tv[3 * t])
    cdef double* b = P(T, T.tv[3 * t + 1])
    cdef double* c = P(T, T.tv[3 * t + 2])
    return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


cdef int convert_to_frontal_edge_set(Aft* A, Tri* T) noexcept nogil:
    """C = every constrained half-edge of an unmeshed triangle (the domain's CDT has
    been built and carved), queued to be taken first (_queue_initial_first).  Also
    counts the triangles for formula (4), and starts the converging rows' lattice
    (lattice.pxi)."""
    cdef int t, k
    queue_clear(A)
    A.nv_input = T.nv
    A.n_meshed = 0
    A.n_unmeshed = 0
    A.area_total = 0.0
    A.area_meshed = 0.0
    for t in range(T.nt):
        if T.tstate[t] == T_MESHED:
            A.n_meshed += 1
        elif T.tstate[t] == T_UNMESHED:
            A.n_unmeshed += 1
            A.area_total += _tri_area(T, t)
            for k in range(3):
                if blocking(T, 3 * t + k):
                    if queue_push(A, T, 3 * t + k):
                        return ERR_NOMEM
    if _queue_initial_first(A):
        return ERR_NOMEM
    return lattice_start(A, T)


# With the shortest-first order, the initial front (the edges on the input segments,
# the first row along the boundary) is taken whole, shortest first, before any edge a
# step made.  Taken by length with the rest, a boundary edge waits for every shorter
# front edge: the rows growing from short input edges (a small island, a staircase's
# steps, a concave corner) reach a longer boundary before its own first row exists,
# and meet its fixed vertices, which smoothing can only slide along their segment;
# with that row in place they meet free vertices instead.  The real-world group's mean
# radius ratio rose from 0.9661 to 0.9669 and its share above 0.9 from 92.97 % to
# 93.63 %, with 3 % fewer triangles (rw-earcut-hilbert +0.0034, rw-river +0.0028 with
# 15 % fewer, rw-city +0.0025; rw-earcut-water-huge2 -0.0011); random discs, ellipses,
# slots and rounded boxes went from 80.9 to 50.1 triangles at or below 0.9 a domain.
# The graded airfoil (naca0012) lost 0.0012 with 7 % more triangles: the rows on its
# chord now grow before the leading edge's fronts spread over them.  Giving the
# boundary's edges a head start of one to four octaves of length instead did about
# as well (0.9668-0.9669); a quarter or half an octave, less (0.9665, 0.9667).


cdef int _queue_initial_first(Aft* A) noexcept nogil:
    """Move the queued edges (the initial front) into A.first in the queue's order;
    queue_pop hands them out before anything queued later.  0 or ERR_NOMEM."""
    cdef int n = A.queue_n, i
    if n == 0 or A.order != ORDER_SHORTEST:
        return 0
    free(A.first)
    A.first = <QueueItem*> malloc(n * sizeof(QueueItem))
    if A.first == NULL:
        return ERR_NOMEM
    for i in range(n):
        queue_pop(A, &A.first[i])
    A.first_n = n
    A.first_pos = 0
    A.queue_n = n
    return 0


cdef int get_next_edge(Aft* A, Tri* T) noexcept nogil:
    """Pop the queue until an entry is still a front edge; NONE when C is empty.
    Half-edges move between slots when triangles are rewritten, so an entry is
    identified by its end points and found again around its origin if needed."""
    cdef QueueItem item
    cdef int e
    while A.queue_n > 0:
        queue_pop(A, &item)
        e = item.he
        if not (e < 3 * T.nt and T.tstate[e // 3] != T_FREE
                and T.tv[e] == item.org and T.tv[nxt(e)] == item.dst):
            e = find_edge(T, item.org, item.dst)
            if e < 0:
                continue
        if is_front(T, e):
            return e
    return NONE


cdef inline int compute_existing_candidate(Tri* T, int e) noexcept nogil:
    return T.tv[prv(e)]


cdef void compute_new_candidate(Aft* A, Tri* T, int e, double* R, double* h_out) noexcept nogil:
    """The ideal point R on the left of E = a->b: on the perpendicular bisector, at the
    distance d from a and b that the local size asks for (an equilateral triangle when
    |E| equals the size), kept between R_SIDE_MIN |E| and R_SIDE_MAX |E| (see
    _side_length) so that the triangle's shape stays good where the size changes
    faster than the front; where the size grows away from E (it is larger at the
    first guess of R than at E's midpoint), by at most R_SIDE_MAX_GROWING |E|.

    Under one constant size, R of an edge in a row from a curved boundary may move
    to the nearest point of one lattice, and so may R of an edge in the rows well
    inside a size field's plateau (lattice.pxi).  Where the unmeshed triangle on an
    input edge E would fill an input corner of about 83 to 150 degrees alone, R goes
    on the corner's bisector instead (_split_wide_corner).

    h_out is the length New_is_preferred's proximity rules measure against: the local
    size, but at most PROXIMITY_PER_SIDE * d, and LATTICE_PROXIMITY times that where
    the size is uniform, up to CONVERGING_PROXIMITY times the size where fronts
    converge (see there for both), and never so long that close_factor times it
    reaches PROXIMITY_REACH_MAX * d."""
    cdef double* pa = P(T, T.tv[e])
    cdef double* pb = P(T, T.tv[nxt(e)])
    cdef double mx = 0.5 * (pa[0] + pb[0]), my = 0.5 * (pa[1] + pb[1])
    cdef double ex = pb[0] - pa[0], ey = pb[1] - pa[1]
    cdef double L = sqrt(ex * ex + ey * ey)
    cdef double h = size_at_from(&A.size, mx, my, T.tv[e], T.tv[nxt(e)])
    cdef double d, height, nx, ny, h_r, hb
    cdef bint uniform
    nx = -ey / L
    ny = ex / L
    # one correction with the size at the first guess, for graded sizes
    d = _side_length(h, L, R_SIDE_MAX)
    height = sqrt(d * d - 0.25 * L * L)
    h_r = size_at(&A.size, mx + nx * height, my + ny * height)
    uniform = (fabs(h_r - h) <= UNIFORM_SIZE_TOLERANCE * h
               and T.tv[prv(e)] >= A.nv_input)
    d = _side_length(0.5 * (h + h_r), L, R_SIDE_MAX_GROWING if h_r > h else R_SIDE_MAX)
    h = 0.5 * (h + h_r)
    height = sqrt(d * d - 0.25 * L * L)
    R[0] = mx + nx * height
    R[1] = my + ny * height
    A.lat_moved = False
    if A.lat_on:
        lattice_snap(A, T, e, R, h)
    h_out[0] = h if h < PROXIMITY_PER_SIDE * d else PROXIMITY_PER_SIDE * d
    if uniform:
        h_out[0] *= LATTICE_PROXIMITY
        if A.size.nt == 0 and L < CONVERGING_EDGE * h and A.close_factor > 0.0:
            hb = CONVERGING_PROXIMITY * h
            if A.close_factor * hb > L:
                hb = L / A.close_factor
            if hb > h_out[0]:
                h_out[0] = hb
    if A.close_factor * h_out[0] > PROXIMITY_REACH_MAX * d:
        h_out[0] = PROXIMITY_REACH_MAX * d / A.close_factor
    _split_wide_corner(A, T, e, R)


# R's distance from the ends of E stays within these multiples of |E|: the triangle
# T(E, R) is then never far from equilateral (radius ratio >= 0.88), and where the
# size differs from |E| it is reached over a few layers (about 1.35 per layer, near
# the default gradation) instead of by one stretched or flattened triangle.
# Where the size is more than R_SIDE_FAR |E| (a short input edge in a coarse region),
# R goes out to R_SIDE_FAR_LENGTH |E| instead: at 1.35 per layer, the many layers
# needed to grow crowd each other where fronts meet (slivers at a sharp trailing edge).
cdef double R_SIDE_MIN = 0.75
cdef double R_SIDE_MAX = 1.35
# Where the size field itself grows away from E (a front leaving short input edges or
# a fine region), a layer grows by at most this: each growing layer is a row of
# isosceles triangles whose radius ratio falls with the growth (0.97 at 1.2, 0.93 at
# 1.35), and these rows were most of what kept the real-world group's mean radius
# ratio below Gmsh's (rings around small holes, transitions off short edges).  A
# few % more triangles there; 1.2 made one case worse, and a uniform size never
# reads it (the size at R equals the size at E), so the squares keep their lattice.
cdef double R_SIDE_MAX_GROWING = 1.22
cdef double R_SIDE_FAR = 3.0
cdef double R_SIDE_FAR_LENGTH = 2.0
# The proximity rules (close_factor * h) measure against at most this multiple of R's
# side d.  Where the size is well above |E| (a short input edge, a coarsening front)
# the raw size made the rule refuse R for vertices about as far as E's own ends
# (0.5 h > d once h > 2.7 |E|): no layer grew there, and the Delaunay apexes left
# flat triangles next to short edges.  1.5 keeps every vertex farther than 0.75 d
# (default close_factor) acceptable; below 1.35 the size transitions of graded cases
# (inclusion, naca0012) got worse in the benchmarks.
cdef double PROXIMITY_PER_SIDE = 1.5
# Where the size is uniform around E (the size at the first guess of R within
# UNIFORM_SIZE_TOLERANCE of the size at E's middle), the proximity rules reach
# LATTICE_PROXIMITY times farther.  There the fronts grow lattices, and where two
# lattices meet out of step (which depends on nothing more than the order of the
# queue), the plain reach let the seam's irregular vertices tilt the next rows: the
# disorder spread in a widening wedge over up to a third of the unit square (at h =
# 0.0018, 0.0014, 0.0009, 0.0005, with 10-40x the smoothing moves per triangle).
# Reaching farther takes the seam's vertices instead: at 1.2 every square from h =
# 0.02 to 0.0005 kept its seams one triangle wide (1.1 still lost h = 0.0005).  Not
# where E's apex is an input vertex: there the longer reach closed a square's 90
# degree corner with one right triangle and left 39 degrees beside it.  Graded
# regions keep the plain reach too: there the longer one made fewer, worse
# triangles in size transitions.
cdef double LATTICE_PROXIMITY = 1.2
cdef double UNIFORM_SIZE_TOLERANCE = 0.005
# Where the size is one constant over the whole domain (no background field), a front
# edge shorter than CONVERGING_EDGE times the size can only come from fronts that
# converge: a ring closing on itself, as in a disc, or fronts meeting.  There the
# proximity rules reach CONVERGING_PROXIMITY times the size (0.8 of it at the default
# close_factor), but never farther than E's own length: R's neighbours in the row,
# closer than E, are taken instead of starting another compressed row.  A disc as a
# 256-gon meshed at its edges' length went from mean radius ratio 0.981 to 0.989
# (Gmsh 0.997), inside radius 0.6 from about 0.986 to 0.999.  Not with a graded
# field: there a short edge may be a row still growing away from short input edges,
# which widens by itself as it moves out, and merging its points made worse
# triangles (rw-gear 0.9825 -> 0.9803, and 0.9793 without the cap at E's length).
cdef double CONVERGING_EDGE = 0.8
cdef double CONVERGING_PROXIMITY = 1.6
# The proximity rules' reach, close_factor times the length above, stays below this
# multiple of R's side d: a lattice's own neighbours are about d from R, and a reach
# that took them in refused R nearly everywhere, so the front closed on existing
# vertices (close_factor from about 0.83 up: the unit square at size 0.02 got 840
# triangles instead of about 5,700).  The default close_factor reaches at most 0.9 d.
cdef double PROXIMITY_REACH_MAX = 0.95


# An input corner between these angles is shared by two triangles: where E and the
# input edge after it (or before it) meet at such a corner, so that the unmeshed
# triangle on E is the one triangle that would fill the corner, R goes on the
# corner's bisector (_split_wide_corner).  From about 81.5 degrees two isosceles
# halves are rounder than one triangle over the whole corner (radius ratio 0.908
# each); a single triangle on a 90 degree corner is a right one (0.83).  On the
# real-world group, with the bisector point at the geometric mean of the edges'
# lengths and no ratio limit (below), 79 / 83 / 87 degrees left 43,213 / 43,063 /
# 43,115 triangles of radius ratio <= 0.9 (44,332 without the rule), and an upper
# end of 120 / 150 / 175 degrees 43,174 / 43,063 / 43,116: beyond it the front's own
# rows share the corner out.  At the arithmetic mean (used) it left 43,044.
cdef double CORNER_SPLIT_MIN = 83.0 * 3.141592653589793 / 180.0
cdef double CORNER_SPLIT_MAX = 150.0 * 3.141592653589793 / 180.0
# ... when the corner's two edges differ in length by at most this factor: between
# a short and a long edge the bisector point makes one half a sliver (43,044 without
# the limit, 43,029 with 1.5, 43,037 with 2)
cdef double CORNER_SPLIT_RATIO = 1.5


cdef void _split_wide_corner(Aft* A, Tri* T, int e, double* R) noexcept nogil:
    """Where the unmeshed triangle (a, b, S) on E = a->b (an input edge) would fill a
    corner between E and the next or previous input edge, at b or at a, of an angle
    between CORNER_SPLIT_MIN and CORNER_SPLIT_MAX, R becomes the point on the
    corner's bisector at the mean length of its two edges, so that T(E, R) takes half
    the corner and the front closes the other half on R.  R is judged by the same
    rules as any other (New_is_preferred, Check_visible, the proximity rules), so the
    guarantees are unchanged; when it is refused, S fills the corner as before."""
    cdef int a = T.tv[e], b = T.tv[nxt(e)], S = T.tv[prv(e)], c, u
    cdef double ux, uy, wx, wy, lu, lw, angle, bx, by, bl, d
    if not (T.eflag[e] & E_SEGMENT) or S < 0:
        return
    if (T.eflag[nxt(e)] & E_SEGMENT) and b < A.nv_input:
        c, u = b, a         # the corner at b, between b -> a and b -> S
    elif (T.eflag[prv(e)] & E_SEGMENT) and a < A.nv_input:
        c, u = a, b         # the corner at a, between a -> b and a -> S
    else:
        return
    ux = T.xy[2 * u] - T.xy[2 * c]
    uy = T.xy[2 * u + 1] - T.xy[2 * c + 1]
    wx = T.xy[2 * S] - T.xy[2 * c]
    wy = T.xy[2 * S + 1] - T.xy[2 * c + 1]
    lu = sqrt(ux * ux + uy * uy)
    lw = sqrt(wx * wx + wy * wy)
    if not (lu > 0.0 and lw > 0.0) or lu > CORNER_SPLIT_RATIO * lw or lw > CORNER_SPLIT_RATIO * lu:
        return
    angle = _angle_at(P(T, c), P(T, u), P(T, S))
    if angle < CORNER_SPLIT_MIN or angle > CORNER_SPLIT_MAX:
        return
    bx = ux / lu + wx / lw
    by = uy / lu + wy / lw
    bl = sqrt(bx * bx + by * by)
    if not bl > 0.0:
        return
    d = 0.5 * (lu + lw)
    R[0] = T.xy[2 * c] + d * bx / bl
    R[1] = T.xy[2 * c + 1] + d * by / bl
    A.lat_moved = False     # not the lattice's point: no retry at the one before it


cdef inline double _side_length(double h, double L, double side_max) noexcept nogil:
    if h < R_SIDE_MIN * L:
        return R_SIDE_MIN * L
    if h > R_SIDE_FAR * L:
        return R_SIDE_FAR_LENGTH * L
    if h > side_max * L:
        return side_max * L
    return h


cdef bint new_is_preferred(Aft* A, Tri* T, int e, const double* R, int S, double h) noexcept nogil:
    """Prefer R only if T(E, R) will be a CDT triangle once R is inserted (Lemma 3.1:
    S strictly outside the circumcircle of T(E, R)), and S is not already about where R
    would go.  Never true when R and S coincide (then |S - R| = 0)."""
    cdef double* pa
    cdef double* pb
    cdef double* ps
    cdef double dx, dy
    if A.greedy:
        return False
    pa = P(T, T.tv[e])
    pb = P(T, T.tv[nxt(e)])
    ps = P(T, S)
    if orient2d(pa, pb, R) <= 0:
        return False
    if incircle(pa, pb, R, ps) >= 0:
        return False
    dx = ps[0] - R[0]
    dy = ps[1] - R[1]
    if dx * dx + dy * dy < (A.close_factor * h) * (A.close_factor * h):
        return False
    return True


cdef bint mesh_size_constraint(Aft* A, Tri* T, int e, const double* R) noexcept nogil:
    """Formula (4): refuse a new vertex when the mesh could then exceed N_max, and
    formula (5): refuse it when T(E, R) would be smaller than A_min.

    For (4): by the appendix's formula (6) the unmeshed CDT, whose vertices all lie on
    C, has exactly N(C) + 2(m - k) triangles (m holes, k components), so
    N(T) + #unmeshed is the final count if no vertex is added from now on, and each
    new vertex adds exactly two.  This is formula (4) with the exact m and k instead of
    the bound 2(m - 1).  (No scaffold is planted under max_triangles, so no scaffold
    vertex is among the unmeshed triangles' vertices here.)"""
    cdef double* pa
    cdef double* pb
    cdef double area
    if A.max_triangles >= 0 and A.n_meshed + A.n_unmeshed + 2 > A.max_triangles:
        return True
    if A.min_area > 0.0:
        pa = P(T, T.tv[e])
        pb = P(T, T.tv[nxt(e)])
        area = 0.5 * ((pb[0] - pa[0]) * (R[1] - pa[1]) - (pb[1] - pa[1]) * (R[0] - pa[0]))
        if area < A.min_area:
            return True
    return False


cdef int _push_lr(Aft* A, bint to_left, int e) noexcept nogil:
    if A.nleft >= A.lr_cap or A.nright >= A.lr_cap:
        if (_grow(<void**> &A.left, 2 * A.lr_cap * sizeof(int32_t))
                or _grow(<void**> &A.right, 2 * A.lr_cap * sizeof(int32_t))):
            return ERR_NOMEM
        A.lr_cap *= 2
    if to_left:
        A.left[A.nleft] = e
        A.nleft += 1
    else:
        A.right[A.nright] = e
        A.nright += 1
    return 0


cdef int check_visible(Aft* A, Tri* T, int e, const double* R) noexcept nogil:
    """Figure 8: walk from the midpoint M of E toward R through the unmeshed CDT.

    Returns 1 (visible; A.vis_loc / A.vis_where say where R lies, ready for insertion)
    or 0 (not visible), or an error.  The crossed edges go to A.left / A.right as in the
    paper (an edge pivoting on the left end of the previous one goes to Right).  The
    walk stops as not visible when it meets a constrained edge, when R is at a vertex or
    on a constrained edge, or when the line of sight passes exactly through a vertex.
    It only moves forward along the segment M R, so it cannot loop; the step cap is a
    guard against a broken structure.

    Visibility from the midpoint suffices only when no node visible from E lies in the
    circumcircle of T(E, R) (the paper's argument), i.e. when S is outside it, Lemma
    3.1's condition: without it the answer is 'not visible'."""
    cdef double* pa = P(T, T.tv[e])
    cdef double* pb = P(T, T.tv[nxt(e)])
    cdef double M[2]
    cdef int g = e, t, u, v, w, o1, o2, ow, steps = 0, exit_e
    A.nleft = 0
    A.nright = 0
    A.vis_loc = -1
    A.vis_where = NONE
    if orient2d(pa, pb, R) <= 0:
        return 0
    if incircle(pa, pb, R, P(T, compute_existing_candidate(T, e))) >= 0:
        return 0
    M[0] = 0.5 * (pa[0] + pb[0])
    M[1] = 0.5 * (pa[1] + pb[1])
    while steps <= T.nt:
        steps += 1
        # triangle (u, v, w) entered through g = u->v: u left, v right of M->R
        u = T.tv[g]
        v = T.tv[nxt(g)]
        w = T.tv[prv(g)]
        if w == GHOST:
            return ERR_INTERNAL
        o1 = orient2d(P(T, v), P(T, w), R)
        o2 = orient2d(P(T, w), P(T, u), R)
        if o1 >= 0 and o2 >= 0:
            if o1 == 0 and o2 == 0:
                return 0                        # R coincides with w
            if o1 == 0:
                if blocking(T, nxt(g)):
                    return 0
                A.vis_loc = LOC_ON_EDGE
                A.vis_where = nxt(g)
                return 1
            if o2 == 0:
                if blocking(T, prv(g)):
                    return 0
                A.vis_loc = LOC_ON_EDGE
                A.vis_where = prv(g)
                return 1
            A.vis_loc = LOC_IN_TRIANGLE
            A.vis_where = g // 3
            return 1
        ow = orient2d(M, R, P(T, w))
        if ow == 0:
            return 0                            # the line of sight runs through w
        if ow > 0:
            exit_e = nxt(g)                     # v->w: w left, pivot on the right end
            if _push_lr(A, True, exit_e):
                return ERR_NOMEM
        else:
            exit_e = prv(g)                     # w->u: w right, pivot on the left end
            if _push_lr(A, False, exit_e):
                return ERR_NOMEM
        if blocking(T, exit_e):
            return 0
        g = T.twin[exit_e]
    return ERR_INTERNAL


cdef inline double _dist2_point_segment(const double* p, const double* a,
                                        const double* b) noexcept nogil:
    cdef double ex = b[0] - a[0], ey = b[1] - a[1]
    cdef double px = p[0] - a[0], py = p[1] - a[1]
    cdef double L2 = ex * ex + ey * ey, s = 0.0
    if L2 > 0.0:
        s = (px * ex + py * ey) / L2
        if s < 0.0:
            s = 0.0
        elif s > 1.0:
            s = 1.0
    px -= s * ex
    py -= s * ey
    return px * px + py * py


cdef inline double _in_circle_value(const double* a, const double* b, const double* c,
                                    const double* d) noexcept nogil:
    """The incircle determinant in plain floating point (> 0: d inside the circle of
    the counter-clockwise a, b, c), for heuristics only: orders and searches that a
    near-tie cannot make wrong."""
    cdef double adx = a[0] - d[0], ady = a[1] - d[1]
    cdef double bdx = b[0] - d[0], bdy = b[1] - d[1]
    cdef double cdx = c[0] - d[0], cdy = c[1] - d[1]
    return ((adx * adx + ady * ady) * (bdx * cdy - cdx * bdy)
            + (bdx * bdx + bdy * bdy) * (cdx * ady - adx * cdy)
            + (cdx * cdx + cdy * cdy) * (adx * bdy - bdx * ady))


cdef inline bint _in_circle_float(const double* a, const double* b, const double* c,
                                  const double* d) noexcept nogil:
    """Plain floating-point incircle: only for is_crowded's heuristic cavity, where a
    wrong answer in a near-tie merely looks at one triangle more or less (the exact
    predicate there cost a tenth of the run time on near-equilateral meshes)."""
    return _in_circle_value(a, b, c, d) > 0.0


cdef int is_crowded(Aft* A, Tri* T, const double* R, double h) noexcept nogil:
    """The part of New_is_preferred that needs to know where R lies (so it runs right
    after check_visible found it): R is refused when it would come closer than
    close_factor * h to a vertex it would be joined to, or closer than EDGE_PROXIMITY
    times that to a constrained edge it would face (the narrow-gap rule).  Those
    vertices and edges belong to R's insertion cavity (the unmeshed triangles whose
    circumcircles contain R, reached without crossing a constraint), because they
    become R's neighbours; only the part of the cavity within close_factor * h of R
    can hold them, so the search stays there.
    Returns 1 (crowded), 0, 2 (a scaffold vertex, A.crowd_scaffold, is that near: it
    goes first), or an error."""
    cdef int n = 0, i, k, e, t, u, j, x, y, z
    cdef double dv2 = (A.close_factor * h) * (A.close_factor * h)
    cdef double de2 = EDGE_PROXIMITY * EDGE_PROXIMITY * dv2
    cdef double dx, dy
    cdef bint seen
    if reserve_stack(T, CROWD_SEARCH_MAX):
        return ERR_NOMEM
    if A.vis_loc == LOC_IN_TRIANGLE:
        T.stack[0] = A.vis_where
        n = 1
    else:
        T.stack[0] = A.vis_where // 3
        T.stack[1] = T.twin[A.vis_where] // 3
        n = 2
    i = 0
    while i < n:
        t = T.stack[i]
        i += 1
        for k in range(3):
            e = 3 * t + k
            x = T.tv[e]
            dx = T.xy[2 * x] - R[0]
            dy = T.xy[2 * x + 1] - R[1]
            if dx * dx + dy * dy < dv2:
                if is_scaffold(A, x):
                    A.crowd_scaffold = x
                    return 2
                return 1
            if blocking(T, e):
                if _dist2_point_segment(R, P(T, x), P(T, T.tv[nxt(e)])) < de2:
                    return 1
                continue
            if n >= CROWD_SEARCH_MAX or _dist2_point_segment(R, P(T, x), P(T, T.tv[nxt(e)])) >= dv2:
                continue            # the triangle beyond lies outside the search disk
            u = T.twin[e] // 3
            seen = False
            for j in range(n):
                if T.stack[j] == u:
                    seen = True
                    break
            if seen:
                continue
            x = T.tv[3 * u]
            y = T.tv[3 * u + 1]
            z = T.tv[3 * u + 2]
            if _in_circle_float(P(T, x), P(T, y), P(T, z), R):
                T.stack[n] = u
                n += 1
    return 0


cdef int add_triangle(Aft* A, Tri* T, int t) noexcept nogil:
    """Mark T(E, U) meshed; its edges towards unmeshed triangles become front edges
    (unless they already were: input segments inside the domain).  Then, if swaps are
    on, flip edges inside the meshed region until it is again the CDT of its vertices,
    the input edges and C (Lawson's flips, as Cline & Renka describe)."""
    cdef int k, e, f
    T.tstate[t] = T_MESHED
    A.n_meshed += 1
    A.n_unmeshed -= 1
    A.area_meshed += _tri_area(T, t)
    for k in range(3):
        e = 3 * t + k
        f = T.twin[e]
        if T.tstate[tri_of(f)] == T_UNMESHED and not (T.eflag[e] & E_SEGMENT):
            if queue_push(A, T, f):
                return ERR_NOMEM
    if A.swaps:
        if reserve_stack(T, 3):
            return ERR_NOMEM
        T.stack[0] = 3 * t
        T.stack[1] = 3 * t + 1
        T.stack[2] = 3 * t + 2
        return legalize_meshed(T, 3)
    return 0


cdef int update_boundary(Aft* A, Tri* T, int e) noexcept nogil:
    """Take T(E, S): the unmeshed triangle on E.  Its state change performs Figure 6's
    edge toggles (see the top of this file); returns that triangle for Add_triangle."""
    return e // 3


cdef int update_internal(Aft* A, Tri* T, int e, const double* R) noexcept nogil:
    """Insert R (located by check_visible) into the unmeshed CDT, then make sure F and
    G are edges.  Returns the triangle T(E, R) for Add_triangle.

    By Lemma 3.1 T(E, R) is a triangle of cd(S(E) + R) when S is outside C(E, R), which
    check_visible has required, so after the Lawson insertion it is normally already
    there; otherwise F and G are inserted as constraints by Cline & Renka's
    retriangulation of exactly the triangles they cross."""
    cdef int a = T.tv[e], b = T.tv[nxt(e)], v, res, f
    v = add_vertex(T, R[0], R[1])
    if v < 0:
        return v
    res = insert_vertex_at(T, v, A.vis_loc, A.vis_where)
    if res < 0:
        return res
    A.n_unmeshed += 2
    A.n_new += 1
    res = lattice_new_vertex(A, T, v, a, b)
    if res < 0:
        return res
    f = find_edge(T, a, b)
    if f < 0:
        return ERR_INTERNAL
    if T.tv[prv(f)] != v:
        A.n_forced += 1
        res = insert_segment(T, a, v, E_FIXED, -1)
        if res < 0:
            return res
        res = insert_segment(T, v, b, E_FIXED, -1)
        if res < 0:
            return res
        f = find_edge(T, a, b)
        if f < 0 or T.tv[prv(f)] != v:
            return ERR_INTERNAL
        # the triangle becomes meshed next, so F and G stay constrained as front edges
        T.eflag[nxt(f)] &= ~E_FIXED
        T.eflag[T.twin[nxt(f)]] &= ~E_FIXED
        T.eflag[prv(f)] &= ~E_FIXED
        T.eflag[T.twin[prv(f)]] &= ~E_FIXED
    return f // 3


cdef int basic_aft_step(Aft* A, Tri* T, int e) noexcept nogil:
    """One pass through Figure 5's while loop for the current edge e.

    The apex S may be a scaffold vertex.  R is then judged against it as against any
    S: if S is outside the circumcircle of T(E, R), so is the apex the CDT would have
    without the scaffold (the circles through E's ends are nested on its left), and
    that apex is only needed when R is not taken.  Then, or when a scaffold vertex is
    too near R, it is removed and the pass starts again on the same edge."""
    cdef double R[2]
    cdef double h
    cdef int S, t, vis, crowded, a = T.tv[e], b = T.tv[nxt(e)]
    cdef bint new
    compute_new_candidate(A, T, e, R, &h)
    while True:
        S = compute_existing_candidate(T, e)
        new = new_is_preferred(A, T, e, R, S, h) and not mesh_size_constraint(A, T, e, R)
        if new:
            vis = check_visible(A, T, e, R)
            if vis < 0:
                return vis
            if vis == 1:
                # is_crowded answers 1 / 0 / 2 or an error code, which must stop the
                # loop rather than read as "crowded"
                crowded = is_crowded(A, T, R, h)
                if crowded < 0:
                    return crowded
                if crowded == 2:
                    e = _remove_in_the_way(A, T, A.crowd_scaffold, a, b)
                    if e < 0:
                        return e
                    continue
                vis = 0 if crowded else 1
            new = vis == 1
        if not new and is_scaffold(A, S):
            e = _remove_in_the_way(A, T, S, a, b)
            if e < 0:
                return e
            continue
        if not new and A.lat_moved:
            # the lattice point was refused (an earlier R took it, or it is not
            # visible): judge the point Compute_new_candidate computed before the move
            A.lat_moved = False
            R[0] = A.lat_plain[0]
            R[1] = A.lat_plain[1]
            continue
        break
    if new:
        t = update_internal(A, T, e, R)
    else:
        t = update_boundary(A, T, e)
    if t < 0:
        return t
    A.n_steps += 1
    return add_triangle(A, T, t)


cdef int _remove_in_the_way(Aft* A, Tri* T, int v, int a, int b) noexcept nogil:
    """Remove scaffold vertex v; returns the front edge a->b (its slot may have
    moved) or an error."""
    cdef int res = remove_scaffold_vertex(A, T, v)
    if res < 0:
        return res
    res = find_edge(T, a, b)
    return res if res >= 0 else ERR_INTERNAL


cdef int check_signals(Aft* A) noexcept nogil:
    """Run Python's signal handlers; if one raised, keep its exception in A (the def
    layer raises it again) and return ERR_INTERRUPTED."""
    if not A.signals_here:
        return 0
    with gil:
        if PyErr_CheckSignals() != 0:
            if A.exc_type == NULL:
                PyErr_Fetch(&A.exc_type, &A.exc_value, &A.exc_tb)
            else:
                PyErr_Clear()
            return ERR_INTERRUPTED
    return 0


cdef int basic_aft_loop(Aft* A, Tri* T) noexcept nogil:
    """Figure 5, compiled: runs without the GIL and takes it back only every few
    thousand steps to let Ctrl-C through and to report progress."""
    cdef int e, res
    cdef int64_t count = 0
    if A.n_steps == 0:
        # a fresh front: the scaffold of a large domain goes in first (scaffold.pxi)
        res = plant_scaffold(A, T)
        if res < 0:
            return res
        A.n_scaffold_planted = res
        A.n_unmeshed += 2 * res
    while True:
        e = get_next_edge(A, T)
        if e == NONE:
            break
        res = basic_aft_step(A, T, e)
        if res < 0:
            return res
        count += 1
        if count % SIGNAL_CHECK_INTERVAL == 0:
            if check_signals(A) != 0:
                return ERR_INTERRUPTED
            if A.progress != NULL and A.area_total > 0:
                with gil:
                    try:
                        (<object> A.progress)(A.area_meshed / A.area_total)
                    except KeyboardInterrupt:
                        return ERR_INTERRUPTED
                    except BaseException:
                        pass                # a broken progress display must not stop meshing
    if A.n_unmeshed != 0 or A.n_scaffold != 0:
        return ERR_INTERNAL
    if A.scaffold_hi > A.scaffold_lo:
        return compact_after_scaffold(A, T)
    return 0
