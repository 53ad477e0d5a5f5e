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
# Uses: halfedge.pxd; predicates.pxi (orient2d); triangulation.pxi (flip);
# smoothing.pxi (_shape).
from halfedge cimport *
from libc.math cimport atan2, fabs, floor
from libc.stdlib cimport calloc, free
from libc.stdint cimport uint8_t

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
        if f < e or T.tstate[e // 3] != T_MESHED or T.tstate[f // 3] != T_MESHED:
            continue
        if T.eflag[e] & (E_SEGMENT | E_FIXED):
            continue
        a = T.tv[e]
        b = T.tv[nxt(e)]
        c = T.tv[prv(e)]
        d = T.tv[prv(f)]
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
        T.vdirty[a] = T.vdirty[b] = T.vdirty[c] = T.vdirty[d] = 1
        flips += 1
    free(x)
    return flips
