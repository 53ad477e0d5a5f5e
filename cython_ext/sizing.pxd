# The compiled size field's storage (routines in sizing.pxi).
from libc.stdint cimport int32_t

cdef struct SizeField:
    double constant     # the size everywhere when nt == 0
    int32_t nv, nt      # background vertices and triangles (nt == 0: a constant)
    double* xy          # 2 per background vertex
    double* w           # the user's size at each vertex, gradation-limited (inf: none)
    double* g           # the smallest size any source asks for there, gradation-limited
    int32_t* tv         # 3 per background triangle, counter-clockwise
    int32_t* nb         # 3 per triangle: the one across the edge opposite vertex k, -1 none
    # derived from the above by size_field_set, so that a look-up reads one triangle's
    # data in one place instead of chasing indices:
    int32_t* op         # 3 per triangle: the far vertex of the neighbour nb[k], -1 none
    # 12 per triangle: for the edge opposite corner k, its start (corner k + 1, so the
    # three starts are the corners) and its direction (corner k + 2 - corner k + 1):
    # the walk's side tests, two products each
    double* tedge
    bint w_finite       # no vertex's w is infinite: the interpolation skips the test
    double rate         # a vertex's size g grows by at most this per unit of distance ...
    double reach        # ... beyond this many times g from the vertex
    int32_t hint        # the triangle the last look-up ended in: the next walk starts there
    # per mesh vertex, the background triangle of the last look-up made from it (-1:
    # none yet), so walks stay short when the front jumps across the domain
    int32_t* vhint
    int32_t vhint_cap
