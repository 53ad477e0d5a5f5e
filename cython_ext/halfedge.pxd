# The kernel's triangulation: flat arrays of half-edges.  This is the one place the
# convention is drawn; every function in cython_ext/ relies on it.
#
#                  v2 = tv[3t+2]
#                   /\
#                  /  \
#    e2 = 3t+2    /    \    e1 = 3t+1
#   (v2 -> v0)   /   t  \  (v1 -> v2)
#               /        \
#              /__________\
#   v0 = tv[3t]  e0 = 3t    v1 = tv[3t+1]
#               (v0 -> v1)
#
# * Triangle t owns the half-edges 3t, 3t+1, 3t+2; its vertices are listed
#   counter-clockwise, and half-edge e runs from tv[e] to tv[nxt(e)] with t on its left.
# * twin[e] is the same edge seen from the neighbouring triangle.  Inside the kernel it
#   is never NONE: the outside of the convex hull is closed by "ghost" triangles whose
#   third vertex is GHOST (a symbolic point at infinity), so every walk and every
#   rotation around a vertex stays inside the arrays.  The public API sees -1 there.
# * eflag[e] holds E_SEGMENT / E_FIXED and is always written on both twins together.
# * eseg[e] is the provenance of a constrained edge: the index of the input segment
#   (the row given to insert_segment) it is a piece of, or -1 (not an input segment:
#   a temporary constraint, or no constraint).  Like eflag it is written on both twins
#   together and moves with the edge through every rewrite (set_tri), so pieces of a
#   split segment and edges rebuilt by a retriangulation keep their segment's id.
# * vhe[v] is one half-edge leaving v (tv[vhe[v]] == v).
# * tstate[t] says whether a triangle is outside the domain, still unmeshed, or meshed;
#   the frontal edge set C of the paper is implicit: a half-edge is a front edge exactly
#   when it is constrained (see blocking()) and its own triangle is unmeshed.
from libc.stdint cimport int8_t, int32_t, uint8_t, uint32_t, int64_t

cdef enum:
    GHOST = -1          # the vertex at infinity of ghost triangles
    NONE = -1           # no half-edge / no triangle

# The named enums below are mirrored in Python by src/aftmesh/_states.py (IntEnums);
# tests/test_states.py checks the two agree through _kernel's *_VALUES dicts.

cdef enum EdgeFlag:     # bits of eflag
    E_SEGMENT = 1       # an input edge (boundary, interface, crack): never flipped
    E_FIXED = 2         # a temporary constraint (F, G while Update_internal inserts them)

cdef enum TriState:     # values of tstate
    T_FREE = 0          # slot not in use (only transiently, inside a re-triangulation)
    T_EXTERIOR = 1      # ghost triangles, outside the domain, holes
    T_UNMESHED = 2      # part of the unmeshed region S(E) of the paper
    T_MESHED = 3        # part of the mesh T built so far

cdef enum Status:       # returned by kernel routines (0 or a count = success)
    ERR_NOMEM = -1
    ERR_CROSSING = -2   # a new edge would cross a constrained edge (T.err_* say which)
    ERR_COLLINEAR = -3  # all points on one line: no triangle exists
    ERR_INTERNAL = -4   # an invariant broke: a bug, reported instead of looping or crashing
    ERR_INTERRUPTED = -5

cdef enum Location:     # results of locate()
    LOC_IN_TRIANGLE = 0
    LOC_ON_EDGE = 1
    LOC_ON_VERTEX = 2
    LOC_OUTSIDE = 3     # strictly outside the convex hull: the answer is a ghost triangle

cdef enum Order:        # Get_next_edge's order of the heap
    # the initial front (shortest first), then the shortest front edge first (length
    # classes, oldest within one)
    ORDER_SHORTEST = 0
    ORDER_LONGEST = 1
    ORDER_OLDEST = 2    # first in, first out

cdef struct Tri:
    double* xy          # 2 doubles per vertex
    int32_t* vhe
    int32_t nv, nv_cap
    int32_t* tv         # 3 per triangle
    int32_t* twin       # 3 per triangle
    uint8_t* eflag      # 3 per triangle
    int32_t* eseg       # 3 per triangle: input segment id, -1 if none
    uint8_t* tstate     # 1 per triangle
    int32_t* tregion    # 1 per triangle
    # slots handed out so far / allocated (no slot is ever given back: every
    # re-triangulation refills the slots it empties)
    int32_t nt, nt_cap
    int32_t last        # a live finite triangle where the next walk starts
    uint32_t rng        # xorshift state for the stochastic walk
    # scratch stacks, grown on demand, never shrunk
    int32_t* stack
    int32_t stack_cap
    int32_t* buf        # chains of the Cline-Renka retriangulation
    int32_t buf_cap
    # where the last ERR_CROSSING came from: new edge (err_a, err_b) hit edge (err_u, err_v)
    int32_t err_a, err_b, err_u, err_v
    int32_t err_seg     # ... which is a piece of input segment err_seg (-1: none)
    # while smoothing runs, per vertex: a VertexMark (legalize_meshed's flips set
    # V_CHANGED for their four corners); else NULL
    uint8_t* vdirty


cdef enum:
    # VertexMarks: what smoothing knows of a vertex since it was last judged
    V_SETTLED = 0       # nothing around it changed: judged again, it would stay
    V_CHANGED = 1       # its ring may have changed (it or a neighbour moved, a flip)
    V_OWES_DESCENT = 2  # it stayed where only the neighbours' mean was tried


# Half-edges are never negative here (callers test for NONE first), and unsigned
# division by 3 compiles to a multiply and a shift, where signed division also needs
# the sign's correction: these run in every rotation and walk.  tri_of stands for
# `e // 3` in the hottest tests (the meshed-edge and ring tests); in flip, the Lawson
# loops and locate it made the compiled kernel run more instructions, not fewer.
cdef inline int nxt(int e) noexcept nogil:
    return e - 2 if <uint32_t> e % 3 == 2 else e + 1

cdef inline int prv(int e) noexcept nogil:
    return e + 2 if <uint32_t> e % 3 == 0 else e - 1

# The same without a branch: smoothing's walks around each vertex it judges, the
# Lawson loops (Delaunay insertion and the meshed region's), the CDT's segment
# insertion, the minimum-angle pass and the chains.  There e % 3 is as good as random,
# and gcc compiles nxt and prv's choice to a branch that callgrind's branch simulation
# found mispredicted about one time in three (2-4 % of the time on the graded real
# outlines).  The front's own steps (front.pxi), the lattice and the scaffold
# keep the branch, which is mostly predicted there: with these forms (a few more
# instructions) everywhere, the uniform squares took 3-4 % longer.
cdef inline int nxt_nb(int e) noexcept nogil:
    return e + 1 - 3 * <int> ((<uint32_t> e % 3) >> 1)

cdef inline int prv_nb(int e) noexcept nogil:
    return e - 1 + 3 * <int> (((<uint32_t> e % 3) - 1) >> 31)

cdef inline int tri_of(int e) noexcept nogil:
    return <int> (<uint32_t> e // 3)

cdef inline double* P(Tri* T, int v) noexcept nogil:
    return &T.xy[2 * v]


cdef inline bint is_ghost(Tri* T, int t) noexcept nogil:
    return T.tv[3 * t] == GHOST or T.tv[3 * t + 1] == GHOST or T.tv[3 * t + 2] == GHOST


cdef inline bint blocking(Tri* T, int e) noexcept nogil:
    """A constrained edge: an input segment, a temporary constraint, or the boundary
    between two triangles of different state (which makes every front edge constrained
    for the walks, flips and retriangulations of the unmeshed CDT)."""
    if T.eflag[e] & (E_SEGMENT | E_FIXED):
        return True
    return T.tstate[e // 3] != T.tstate[T.twin[e] // 3]
