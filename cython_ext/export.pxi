# The domain's triangles as compact arrays (numbered 0.. without the ghost, free and,
# unless asked for, exterior slots), for Triangulation.arrays().
#
# Uses: halfedge.pxd (Tri, enums, nxt, is_ghost); nothing else of the kernel.
from halfedge cimport *


cdef int mark_output(Tri* T, bint include_exterior, uint8_t* keep) noexcept nogil:
    """keep[t] = 1 for the triangles of the output (unmeshed or meshed; finite exterior
    ones too with include_exterior); returns their number."""
    cdef int t, n = 0
    for t in range(T.nt):
        keep[t] = (T.tstate[t] == T_UNMESHED or T.tstate[t] == T_MESHED or (
            include_exterior and T.tstate[t] == T_EXTERIOR and not is_ghost(T, t)))
        n += keep[t]
    return n


cdef int number_output(Tri* T, const uint8_t* keep, int32_t* tri_index, int32_t* vmap,
                       int32_t* tris, int32_t* regions) noexcept nogil:
    """Number the kept triangles (tri_index, -1 elsewhere on entry) and their vertices
    (vmap, -1 on entry) in slot order; tris[3i + k] = output vertex k of output
    triangle i, regions[i] its region.  Returns the number of output vertices.
    tris may be T.tv and regions T.tregion: output triangle i is never after slot
    i, and each entry is read before its place is written."""
    cdef int t, k, u, ntri = 0, nvo = 0
    for t in range(T.nt):
        if keep[t]:
            tri_index[t] = ntri
            regions[ntri] = T.tregion[t]
            for k in range(3):
                u = T.tv[3 * t + k]
                if vmap[u] < 0:
                    vmap[u] = nvo
                    nvo += 1
                tris[3 * ntri + k] = vmap[u]
            ntri += 1
    return nvo


cdef void output_points(Tri* T, const int32_t* vmap, double* pts) noexcept nogil:
    cdef int u
    for u in range(T.nv):
        if vmap[u] >= 0:
            pts[2 * vmap[u]] = T.xy[2 * u]
            pts[2 * vmap[u] + 1] = T.xy[2 * u + 1]


cdef int output_segments(Tri* T, const uint8_t* keep, int32_t* segs,
                         int32_t* ids) noexcept nogil:
    """segs / ids = the input-segment edges of the output, each once, by kernel
    vertex (see renumber), with their segment ids; with segs == NULL only counts
    them.  Returns the number of segments."""
    cdef int t, k, e, u, ns = 0
    for t in range(T.nt):
        if not keep[t]:
            continue
        for k in range(3):
            e = 3 * t + k
            if T.eflag[e] & E_SEGMENT:
                u = T.twin[e] // 3
                if not keep[u] or u > t:
                    if segs != NULL:
                        segs[2 * ns] = T.tv[e]
                        segs[2 * ns + 1] = T.tv[nxt(e)]
                        ids[ns] = T.eseg[e]
                    ns += 1
    return ns


cdef void renumber(int32_t* ids, int n, const int32_t* vmap) noexcept nogil:
    """ids[i] = vmap[ids[i]] for the first n."""
    cdef int i
    for i in range(n):
        ids[i] = vmap[ids[i]]


cdef void output_neighbors(Tri* T, const uint8_t* keep, const int32_t* tri_index,
                           int32_t* nbr) noexcept nogil:
    """nbr[3i + k] = the output triangle across the edge opposite vertex k of output
    triangle i, -1 where there is none (tri_index is -1 off the output).  Reads only
    T.twin, which nbr may be: a triangle's three twins are read before its row is
    written, and output triangle i is never after slot i."""
    cdef int t, u0, u1, u2, i
    for t in range(T.nt):
        if not keep[t]:
            continue
        # the edge opposite vertex k is half-edge 3t + (k+1) % 3
        u0 = T.twin[3 * t + 1] // 3
        u1 = T.twin[3 * t + 2] // 3
        u2 = T.twin[3 * t] // 3
        i = tri_index[t]
        nbr[3 * i] = tri_index[u0]
        nbr[3 * i + 1] = tri_index[u1]
        nbr[3 * i + 2] = tri_index[u2]
