# The domain inside the triangulation: flood fills that carve the outside and the
# holes, give regions to the pieces that segments separate, and find those pieces.
#
# Uses: halfedge.pxd (Tri, enums, P, is_ghost); triangulation.pxi (reserve_stack,
# locate); no Python objects, so every routine here runs without the GIL.
from halfedge cimport *


# ---------------------------------------------------------------- flood fills

cdef int flood(Tri* T, int nseed, uint8_t from_state, uint8_t to_state, int32_t region,
               bint set_region) noexcept nogil:
    """Spread from the triangles T.stack[0:nseed] across edges that are not segments,
    changing every reached triangle of state from_state to to_state (and its region)."""
    cdef int sp = nseed, t, k, e, u
    while sp > 0:
        sp -= 1
        t = T.stack[sp]
        if T.tstate[t] != from_state:
            continue
        T.tstate[t] = to_state
        if set_region:
            T.tregion[t] = region
        for k in range(3):
            e = 3 * t + k
            if T.eflag[e] & E_SEGMENT:
                continue
            u = T.twin[e] // 3
            if T.tstate[u] == from_state:
                if reserve_stack(T, sp + 1):
                    return ERR_NOMEM
                T.stack[sp] = u
                sp += 1
    return 0


# Seeds of the flood fills: hole and region points located in the triangulation.

cdef bint _vertex_on_segment(Tri* T, int v) noexcept nogil:
    """Whether a constrained edge ends at v (a seed located on v lies on a segment)."""
    cdef int e0 = T.vhe[v], e = e0
    while True:
        if T.eflag[e] & E_SEGMENT:
            return True
        e = T.twin[prv(e)]
        if e == e0:
            return False


cdef int _seed_triangle(Tri* T, int loc, int where) noexcept nogil:
    """The triangle a flood fill starts from for a seed point located at (loc, where)."""
    if loc == LOC_IN_TRIANGLE:
        return where
    if loc == LOC_ON_EDGE:
        return where // 3
    if loc == LOC_ON_VERTEX:
        return T.vhe[where] // 3
    return NONE


# ---------------------------------------------------------------- the domain

cdef int carve_domain(Tri* T, const double* holes, int nholes, bint from_hull) noexcept nogil:
    """Mark as exterior the triangles reachable without crossing a segment from the
    ghost triangles (if `from_hull`; otherwise only the ghosts themselves) and from
    each hole point holes[2i], holes[2i+1]."""
    cdef int t, n = 0, res, i, where = NONE, loc, seed
    if reserve_stack(T, T.nt):
        return ERR_NOMEM
    for t in range(T.nt):
        if T.tstate[t] != T_FREE and is_ghost(T, t):
            if from_hull:
                T.stack[n] = t
                n += 1
            else:
                T.tstate[t] = T_EXTERIOR
    res = flood(T, n, T_UNMESHED, T_EXTERIOR, 0, False)
    for i in range(nholes):
        if res < 0:
            break
        loc = locate(T, &holes[2 * i], NONE, &where)
        if loc < 0:
            return loc
        seed = _seed_triangle(T, loc, where)
        if seed >= 0:
            T.stack[0] = seed
            res = flood(T, 1, T_UNMESHED, T_EXTERIOR, 0, False)
    return res


cdef int assign_regions(Tri* T, const double* seeds, const int32_t* ids,
                        int n) noexcept nogil:
    """Give region id ids[k] to every domain triangle reachable from the point
    seeds[2k], seeds[2k+1] without crossing a segment (later seeds win)."""
    cdef int i, res, where = NONE, loc, t
    for i in range(n):
        loc = locate(T, &seeds[2 * i], NONE, &where)
        if loc < 0:
            return loc
        t = _seed_triangle(T, loc, where)
        if t < 0 or T.tstate[t] != T_UNMESHED:
            continue
        # flood by a temporary state so that region boundaries need no marker
        T.stack[0] = t
        res = flood(T, 1, T_UNMESHED, T_MESHED, ids[i], True)
        if res < 0:
            return res
        for t in range(T.nt):
            if T.tstate[t] == T_MESHED:
                T.tstate[t] = T_UNMESHED
    return 0


cdef inline double twice_area(Tri* T, int t) noexcept nogil:
    cdef double* a = P(T, T.tv[3 * t])
    cdef double* b = P(T, T.tv[3 * t + 1])
    cdef double* c = P(T, T.tv[3 * t + 2])
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


cdef int domain_components(Tri* T, int32_t* comp, int32_t* best) noexcept nogil:
    """Split the domain (unmeshed) triangles into the pieces that segments separate:
    comp[t] = piece of triangle slot t (comp is -1 everywhere on entry; it stays -1
    for the others), best[c] = the triangle of piece c with the largest area (whose
    centroid is a probe point well inside the piece).  comp and best hold T.nt
    entries.  Returns the number of pieces, or an error."""
    cdef int t, k, e, u, sp, nc = 0, best_t = 0
    cdef double area, best_area
    if reserve_stack(T, T.nt + 1):
        return ERR_NOMEM
    for t in range(T.nt):
        if T.tstate[t] != T_UNMESHED or comp[t] >= 0:
            continue
        best_area = -1.0
        comp[t] = nc
        T.stack[0] = t
        sp = 1
        while sp > 0:
            sp -= 1
            u = T.stack[sp]
            area = twice_area(T, u)
            if area > best_area:
                best_area = area
                best_t = u
            for k in range(3):
                e = 3 * u + k
                if T.eflag[e] & E_SEGMENT:
                    continue
                e = T.twin[e] // 3
                if T.tstate[e] == T_UNMESHED and comp[e] < 0:
                    comp[e] = nc
                    T.stack[sp] = e
                    sp += 1
        best[nc] = best_t
        nc += 1
    return nc


cdef void set_regions(Tri* T, const int32_t* comp, int ncomp,
                      const int32_t* region_of_comp) noexcept nogil:
    """Give every domain triangle t < ncomp the region of its piece comp[t] (see
    domain_components); pieces whose region is -1 (holes, outside) become exterior."""
    cdef int t, r
    for t in range(min(T.nt, ncomp)):
        if comp[t] < 0 or T.tstate[t] != T_UNMESHED:
            continue
        r = region_of_comp[comp[t]]
        if r < 0:
            T.tstate[t] = T_EXTERIOR
        else:
            T.tregion[t] = r
