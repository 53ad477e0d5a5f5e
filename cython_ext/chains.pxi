# Chains: the pieces of one input segment, between two input vertices.  The boundary's
# discretization and the minimum-angle pass split input segments; every vertex they
# put on one (numbered from n_corner on, with exactly two segment pieces) lies inside
# a chain, and the chain's ends give the line of its input segment, on which new
# points are computed (ARCHITECTURE.md's rounding rules).  refine.pxi and sliding.pxi
# use them.
#
# Uses: halfedge.pxd; refine.pxi (ROTATION_CAP).
from halfedge cimport *
from libc.stdlib cimport malloc, free, realloc
from libc.string cimport memset
from libc.stdint cimport int32_t


cdef int chain_ends(Tri* T, int n_corner, int32_t* vend) noexcept nogil:
    """vend[2v], vend[2v+1] = the ends of the chain of segment pieces through v, for
    every vertex inside a chain (not an input vertex, exactly two segment pieces);
    NONE for the others.  vend holds 2 T.nv entries.  Returns 0 or an error."""
    cdef int t, k, e, u, w, prev, nxtv, f, n, guard, i, nseg = 0, cap = 256
    cdef int32_t* grown
    # the segment pieces' half-edges, in the sweep's order (which end of a chain is
    # walked last decides vend's order): the walks below then visit no other edge
    cdef int32_t* seg = <int32_t*> malloc(cap * sizeof(int32_t))
    cdef int32_t* deg = <int32_t*> malloc((T.nv + 1) * sizeof(int32_t))
    if deg == NULL or seg == NULL:
        free(deg)
        free(seg)
        return ERR_NOMEM
    for k in range(2 * T.nv):
        vend[k] = NONE
    memset(deg, 0, (T.nv + 1) * sizeof(int32_t))
    for t in range(T.nt):
        if T.tstate[t] == T_FREE:
            continue
        for k in range(3):
            e = 3 * t + k
            if (T.eflag[e] & E_SEGMENT) and T.tv[e] >= 0:
                deg[T.tv[e]] += 1
                if nseg == cap:
                    cap *= 2
                    grown = <int32_t*> realloc(seg, cap * sizeof(int32_t))
                    if grown == NULL:
                        free(deg)
                        free(seg)
                        return ERR_NOMEM
                    seg = grown
                seg[nseg] = e
                nseg += 1
    for i in range(nseg):
        e = seg[i]
        u = T.tv[e]
        if u >= n_corner and deg[u] == 2:
            continue
        # walk from the chain end u along e to the other end; then mark the inside
        prev = u
        w = T.tv[nxt_nb(e)]
        n = 0
        while w >= n_corner and deg[w] == 2 and n <= T.nv:
            f = T.vhe[w]
            guard = 0
            while not (T.eflag[f] & E_SEGMENT) or T.tv[nxt_nb(f)] == prev:
                f = T.twin[prv_nb(f)]
                guard += 1
                if guard > ROTATION_CAP:
                    free(deg)
                    free(seg)
                    return ERR_INTERNAL
            nxtv = T.tv[nxt_nb(f)]
            vend[2 * w] = u
            prev = w
            w = nxtv
            n += 1
        # second pass: the far end is w; write it on the same vertices
        prev = u
        nxtv = T.tv[nxt_nb(e)]
        while nxtv != w:
            vend[2 * nxtv + 1] = w
            f = T.vhe[nxtv]
            while not (T.eflag[f] & E_SEGMENT) or T.tv[nxt_nb(f)] == prev:
                f = T.twin[prv_nb(f)]
            prev = nxtv
            nxtv = T.tv[nxt_nb(f)]
    free(deg)
    free(seg)
    return 0
