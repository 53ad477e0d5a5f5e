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


cdef enum:
    SEED_ON_SEGMENT = 255   # seed_state: the point lies on a segment (no tstate value)


cdef int seed_state(Tri* T, const double* p) noexcept nogil:
    """The state of the triangle holding p (T_EXTERIOR outside the hull), or
    SEED_ON_SEGMENT when p lies on a segment or on a vertex that a segment ends at (it
    belongs to no single region): what a hole or region point is checked by.  Returns
    an error when the walk fails."""
    cdef int where = NONE, loc = locate(T, p, NONE, &where)
    if loc < 0:
        return loc
    if loc == LOC_IN_TRIANGLE:
        return T.tstate[where]
    if loc == LOC_ON_EDGE:
        return SEED_ON_SEGMENT if T.eflag[where] & E_SEGMENT else T.tstate[where // 3]
    if loc == LOC_ON_VERTEX:
        return SEED_ON_SEGMENT if _vertex_on_segment(T, where) else T.tstate[T.vhe[where] // 3]
    return T_EXTERIOR


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


# Rings that meet nowhere nest: the outside, a part's interior, a hole in it, a part in
# that hole, ...  A piece's depth there is found by this many sweeps over the segments
# at most (each reaches at least one ring deeper); a deeper nest declines to the probes.
cdef enum:
    NESTING_MAX_SWEEPS = 64


cdef int nested_regions(Tri* T, const int32_t* piece_edge, const int32_t* edge_source,
                        const int32_t* ring_polygon) noexcept nogil:
    """The regions of the pieces of a valid multipolygon whose rings meet nowhere
    (inputs.proved_polygon proves it): every segment then has the inside on one side
    and not on the other, so a piece is inside exactly when an odd number of rings
    separates it from the outside, which the carve from the hull left exterior; its
    region is the polygon of the rings around it (ring_polygon, by source: the
    segment's input edge piece_edge, that edge's source edge_source).  Holes and the
    pieces in them get -1.  Returns 1 when it set the regions, 0 when the pieces do not
    nest so (a segment with one piece on both sides or on both sides the same parity,
    an inside piece within two polygons' rings, a piece not reached within
    NESTING_MAX_SWEEPS): the stages then classify by probes; or an error."""
    cdef int t, nc, res = 1
    cdef int n = T.nt if T.nt > 0 else 1
    cdef int32_t* comp = <int32_t*> malloc(n * sizeof(int32_t))
    cdef int32_t* best = <int32_t*> malloc(n * sizeof(int32_t))
    cdef int32_t* sides = <int32_t*> malloc(3 * n * sizeof(int32_t))
    cdef int32_t* region = NULL
    cdef int8_t* odd = NULL
    if comp == NULL or best == NULL or sides == NULL:
        res = ERR_NOMEM
    else:
        for t in range(T.nt):
            comp[t] = -1
        nc = domain_components(T, comp, best)
        if nc < 0:
            res = nc
        else:
            region = <int32_t*> malloc((nc if nc > 0 else 1) * sizeof(int32_t))
            odd = <int8_t*> malloc(nc if nc > 0 else 1)
            if region == NULL or odd == NULL:
                res = ERR_NOMEM
            else:
                res = _nest(T, comp, nc, sides, odd)
                if res > 0:
                    res = _regions_of_odd(T, comp, nc, sides, odd, piece_edge, edge_source,
                                          ring_polygon, region)
                if res > 0:
                    set_regions(T, comp, T.nt, region)
    free(comp)
    free(best)
    free(sides)
    free(region)
    free(odd)
    return res


cdef int _nest(Tri* T, const int32_t* comp, int nc, int32_t* sides,
               int8_t* odd) noexcept nogil:
    """odd[c]: the parity of the rings between piece c and the outside (see
    nested_regions); sides gets the segment half-edges of domain triangles, ended by
    -1.  Returns 1, or 0 where the pieces do not nest."""
    cdef int e, f, a, b, k, ns = 0, sweep
    cdef bint changed = True
    for a in range(nc):
        odd[a] = -1
    for e in range(3 * T.nt):
        if not T.eflag[e] & E_SEGMENT or T.tstate[e // 3] != T_UNMESHED:
            continue
        sides[ns] = e
        ns += 1
        if T.tstate[T.twin[e] // 3] != T_UNMESHED:
            odd[comp[e // 3]] = 1           # across the segment: the carved outside
    sides[ns] = -1
    sweep = 0
    while changed:
        if sweep == NESTING_MAX_SWEEPS:
            return 0
        sweep += 1
        changed = False
        for k in range(ns):
            e = sides[k]
            f = T.twin[e]
            if T.tstate[f // 3] != T_UNMESHED:
                continue
            a = comp[e // 3]
            b = comp[f // 3]
            if a == b or (odd[a] >= 0 and odd[a] == odd[b]):
                return 0
            if odd[a] >= 0 and odd[b] < 0:
                odd[b] = 1 - odd[a]
                changed = True
    for a in range(nc):
        if odd[a] < 0:
            return 0
    return 1


cdef int _regions_of_odd(Tri* T, const int32_t* comp, int nc, const int32_t* sides,
                         const int8_t* odd, const int32_t* piece_edge,
                         const int32_t* edge_source, const int32_t* ring_polygon,
                         int32_t* region) noexcept nogil:
    """region[c]: the polygon of the rings around each odd piece c (they must agree),
    -1 for the even ones.  Returns 1, or 0 where they disagree."""
    cdef int k, c, r
    for c in range(nc):
        region[c] = -1
    k = 0
    while sides[k] >= 0:
        c = comp[sides[k] // 3]
        k += 1
        if not odd[c]:
            continue
        r = ring_polygon[edge_source[piece_edge[T.eseg[sides[k - 1]]]]]
        if region[c] >= 0 and region[c] != r:
            return 0
        region[c] = r
    for c in range(nc):
        if odd[c] and region[c] < 0:
            return 0
    return 1
