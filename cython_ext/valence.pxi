# Valence flips between smoothing rounds (smoothing.pxi decides when).
#
# Smoothing moves vertices but never changes which vertices are joined: the Delaunay
# swaps after each move only restore the empty-circle property.  Where fronts met,
# the mesh keeps vertices of five and of seven triangles that no placement makes
# equilateral (on the real-world group of the benchmarks about a quarter of the
# interior vertices, and the triangles at them have a mean radius ratio of 0.96
# against 0.99 at vertices of six).  So once, after a first smoothing round, an edge
# between two meshed triangles is flipped when that brings its four vertices closer
# to their ideal numbers of triangles: six inside, and at a vertex Basic_aft did not
# create (on the boundary, an input point) its angle over 60 degrees, at least one.
# The flip must lower the sum of the four squared excesses (an integer, so the flips
# end), the quadrilateral must be strictly convex (exact orient2d), and neither new
# triangle may be shaped worse than VALENCE_MIN_SHAPE.
#
# The flipped mesh is not Delaunay.  smoothing.pxi then moves the vertices one round
# without swaps, so that they settle into the new connectivity, and restores the
# constrained Delaunay property by Lawson flips from every triangle with a flipped or
# moved vertex (an edge's empty-circle test reads only the vertices of its two
# triangles, so no other edge can have become illegal).  Flips that the settled
# vertices do not support are undone there; the rest stay, and the final mesh is the
# CDT of its vertices and the input edges as before.
#
# Uses: halfedge.pxd; aft.pxd (Aft: the triangle cap and counts); predicates.pxi
# (orient2d); triangulation.pxi (flip, locate, add_vertex, insert_vertex_at);
# smoothing.pxi (_shape).
from halfedge cimport *
from aft cimport Aft
from libc.math cimport atan2, fabs, floor
from libc.stdlib cimport calloc, free
from libc.stdint cimport uint8_t, int32_t

# A flip that would make a triangle flatter than this (_shape: 1 equilateral; 0.6 is
# an isosceles triangle of about 22 degrees) is not made: the settling round does not
# always mend it, and at 0.3 such triangles became the smallest angle of several
# benchmark meshes (holes-0.01 39.9 -> 34.0 degrees).  From 0.75 on, most of the gain
# in mean radius ratio is lost.
cdef double VALENCE_MIN_SHAPE = 0.6
# 60 degrees: the angle of a vertex's ideal triangle
cdef double VALENCE_ANGLE = 3.141592653589793 / 3.0


cdef inline double _angle_at(const double* p, const double* q, const double* r) noexcept nogil:
    """The angle at p of the triangle p, q, r, in radians."""
    cdef double ux = q[0] - p[0], uy = q[1] - p[1], vx = r[0] - p[0], vy = r[1] - p[1]
    return atan2(fabs(ux * vy - uy * vx), ux * vx + uy * vy)


cdef int _excess_counts(Tri* T, int first_movable, int* excess) noexcept nogil:
    """excess[v] = v's meshed triangles minus its ideal number (see the top); 0 or
    ERR_NOMEM."""
    cdef int t, k, v, ideal
    cdef double* angle = <double*> calloc(first_movable if first_movable > 0 else 1,
                                          sizeof(double))
    if angle == NULL:
        return ERR_NOMEM
    for t in range(T.nt):
        if T.tstate[t] != T_MESHED:
            continue
        for k in range(3):
            v = T.tv[3 * t + k]
            excess[v] += 1
            if v < first_movable:
                angle[v] += _angle_at(P(T, v), P(T, T.tv[3 * t + (k + 1) % 3]),
                                      P(T, T.tv[3 * t + (k + 2) % 3]))
    for v in range(T.nv):
        if v < first_movable:
            ideal = <int> floor(angle[v] / VALENCE_ANGLE + 0.5)
            excess[v] -= ideal if ideal > 1 else 1
        else:
            excess[v] -= 6
    free(angle)
    return 0


cdef inline bint _flip_helps(const int* x, int a, int b, int c, int d) noexcept nogil:
    """Flipping edge a-b (apexes c, d) lowers the sum of the four squared excesses:
    a and b lose a triangle, c and d gain one.  The difference of the two sums is
    2 (x[c] + x[d] - x[a] - x[b]) + 4."""
    return x[c] + x[d] - x[a] - x[b] + 2 < 0


cdef int valence_flips(Tri* T, int first_movable, uint8_t* touched) noexcept nogil:
    """One sweep of valence flips over the meshed edges (see the top of this file);
    the four vertices of each flip are marked in touched and in T.vdirty.  Returns the
    number of flips, or ERR_NOMEM."""
    cdef int e, f, a, b, c, d, flips = 0
    cdef int* x = <int*> calloc(T.nv if T.nv > 0 else 1, sizeof(int))
    if x == NULL:
        return ERR_NOMEM
    if _excess_counts(T, first_movable, x):
        free(x)
        return ERR_NOMEM
    for e in range(3 * T.nt):
        f = T.twin[e]
        if f < e or T.tstate[tri_of(e)] != T_MESHED or T.tstate[tri_of(f)] != T_MESHED:
            continue
        if T.eflag[e] & (E_SEGMENT | E_FIXED):
            continue
        a = T.tv[e]
        b = T.tv[nxt_nb(e)]
        c = T.tv[prv_nb(e)]
        d = T.tv[prv_nb(f)]
        if a < first_movable and b < first_movable and c < first_movable and d < first_movable:
            continue            # none of them moves: the Delaunay swaps would undo it
        if not _flip_helps(x, a, b, c, d):
            continue
        # the new triangles (c, a, d) and (d, b, c): convex and not flat
        if orient2d(P(T, c), P(T, a), P(T, d)) <= 0 or orient2d(P(T, d), P(T, b), P(T, c)) <= 0:
            continue
        if (_shape(P(T, c), P(T, a), P(T, d)) < VALENCE_MIN_SHAPE
                or _shape(P(T, d), P(T, b), P(T, c)) < VALENCE_MIN_SHAPE):
            continue
        flip(T, e)
        x[a] -= 1
        x[b] -= 1
        x[c] += 1
        x[d] += 1
        touched[a] = touched[b] = touched[c] = touched[d] = 1
        T.vdirty[a] = T.vdirty[b] = T.vdirty[c] = T.vdirty[d] = V_CHANGED
        flips += 1
    free(x)
    return flips


# ------------------------------------------------------------------ splits
#
# A vertex Basic_aft made that is in eight triangles or more, among vertices of six,
# is one no flip helps: a flip takes a triangle from it and from one neighbour and
# gives one to two others, so the excesses only move (the sum above does not fall).
# Its triangles are the flattest of the interior (mean radius ratio 0.925 on rw-gear,
# whose whole mesh has 0.984).  valence_splits puts a new point SPLIT_AT of the
# way along its longest edge: the Delaunay flips of the insertion give the new point
# some of its triangles, and the smoothing rounds that follow share the ring out
# between the two.  The point is inserted like any other (insert_vertex_at: Lawson
# flips), so the mesh stays the CDT of its vertices and the input edges; each vertex
# is looked at once a call, so the splits end; each adds two triangles, and none is
# made that would take the mesh past max_triangles.

# the fewest triangles at a vertex Basic_aft made for valence_splits to split it
cdef int SPLIT_VALENCE = 8
# where the new point goes along the longest edge: nearer the vertex it relieves than
# the middle, so the far end keeps its ring (splitting after the last round only,
# 0.2, 0.25 and 0.3 gave the benchmarks' real-world group the same mean radius ratio;
# 0.5 left rw-gear's 0.0003 lower)
cdef double SPLIT_AT = 0.25
# the splits before the first round leave a vertex to the valence flips when one of
# its neighbours that Basic_aft made is in this many triangles or fewer: a flip then
# gives that neighbour one of its triangles and helps both, where a split first left
# the neighbour at four (a radius ratio of 0.71 at a straight side, in
# test_rows_from_a_small_hole_meet_the_first_row_of_a_straight_side).  At five (in
# both passes) the splits lost most of their gain: most vertices of eight have a
# neighbour of five.
cdef int SPLIT_DEFICIENT = 4


cdef int _valence_split_point(Tri* T, int v, double* p) noexcept nogil:
    """The point to split v at (see above), in p; the triangle to locate it from, or
    -1 when v has no unconstrained edge or is not surrounded by meshed triangles."""
    cdef int e0 = T.vhe[v], e = e0, u, t = -1, guard = 0
    cdef double best = -1.0, d2
    cdef double* pv = P(T, v)
    cdef double* pu
    if e0 < 0:
        return -1
    while True:
        u = T.tv[nxt_nb(e)]
        if u < 0 or T.tstate[e // 3] != T_MESHED or guard > T.nt:
            return -1
        pu = P(T, u)
        d2 = (pu[0] - pv[0]) * (pu[0] - pv[0]) + (pu[1] - pv[1]) * (pu[1] - pv[1])
        if d2 > best and not (T.eflag[e] & (E_SEGMENT | E_FIXED)):
            best = d2
            t = e // 3
            p[0] = pv[0] + SPLIT_AT * (pu[0] - pv[0])
            p[1] = pv[1] + SPLIT_AT * (pu[1] - pv[1])
        guard += 1
        e = T.twin[prv_nb(e)]
        if e == e0:
            return t


cdef bint _meshed_in(Tri* T, int loc, int where, int32_t region) noexcept nogil:
    # the place locate() found is inside meshed triangles of the region, off segments
    if loc == LOC_IN_TRIANGLE:
        return T.tstate[where] == T_MESHED and T.tregion[where] == region
    if loc != LOC_ON_EDGE or T.eflag[where] & (E_SEGMENT | E_FIXED):
        return False
    return (T.tstate[where // 3] == T_MESHED and T.tregion[where // 3] == region
            and T.tstate[T.twin[where] // 3] == T_MESHED)


cdef bint _next_to_deficient(Tri* T, int v, int first_movable, int nv0,
                             const int* n) noexcept nogil:
    # a neighbour of v in first_movable..nv0 - 1 (n counts their triangles; the points
    # this pass has added are not counted) is in SPLIT_DEFICIENT triangles or fewer
    cdef int e0 = T.vhe[v], e = e0, u, guard = 0
    while e0 >= 0 and guard <= T.nt:
        u = T.tv[nxt_nb(e)]
        if first_movable <= u < nv0 and n[u] <= SPLIT_DEFICIENT:
            return True
        guard += 1
        e = T.twin[prv_nb(e)]
        if e == e0:
            break
    return False


cdef int valence_splits(Aft* A, Tri* T, int first_movable, bint early) noexcept nogil:
    """Split each vertex from first_movable on that is in SPLIT_VALENCE meshed
    triangles or more (counted before the first split; see above), except, when
    `early` (before the valence flips), one next to a vertex of SPLIT_DEFICIENT or
    fewer.  The new triangles count in A.n_meshed and the new points in A.n_split.
    Returns the number of points inserted (they are the last vertices), or an
    error."""
    cdef int v, t, loc, where, w, res = 0, nv0 = T.nv, count = 0
    cdef double p[2]
    cdef int* n = <int*> calloc(nv0 if nv0 > 0 else 1, sizeof(int))
    if n == NULL:
        return ERR_NOMEM
    for t in range(T.nt):
        if T.tstate[t] == T_MESHED:
            n[T.tv[3 * t]] += 1
            n[T.tv[3 * t + 1]] += 1
            n[T.tv[3 * t + 2]] += 1
    for v in range(first_movable, nv0):
        if n[v] < SPLIT_VALENCE:
            continue
        if A.max_triangles >= 0 and A.n_meshed + 2 > A.max_triangles:
            break
        if early and _next_to_deficient(T, v, first_movable, nv0, n):
            continue
        t = _valence_split_point(T, v, p)
        if t < 0:
            continue
        where = NONE
        loc = locate(T, p, t, &where)
        if loc < 0:
            res = loc
            break
        if not _meshed_in(T, loc, where, T.tregion[t]):
            continue
        w = add_vertex(T, p[0], p[1])
        res = w if w < 0 else insert_vertex_at(T, w, loc, where)
        if res < 0:
            break
        A.n_meshed += 2
        A.n_split += 1
        count += 1
    free(n)
    return res if res < 0 else count
