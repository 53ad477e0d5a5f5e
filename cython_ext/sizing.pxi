# The compiled size field: target edge length h(x, y) read by Compute_new_candidate.
#
# A background grid of nx * ny nodes over a rectangle, interpolated bilinearly and
# clamped outside it; a 1 x 1 grid is a constant.  The Python layer fills the grid by
# sampling the user's size (a number or a callable evaluated on whole arrays at once),
# so the compiled loop never calls back into Python.

cdef struct SizeField:
    double x0, y0       # lower-left grid node
    double dx, dy       # node spacing
    int nx, ny          # nodes per row / per column
    double* h           # h[j * nx + i] at (x0 + i dx, y0 + j dy)


cdef inline double size_at(const SizeField* S, double x, double y) noexcept nogil:
    cdef double fx, fy, tx, ty
    cdef int i, j
    if S.nx == 1 and S.ny == 1:
        return S.h[0]
    fx = (x - S.x0) / S.dx if S.nx > 1 else 0.0
    fy = (y - S.y0) / S.dy if S.ny > 1 else 0.0
    if not fx > 0.0:        # also catches NaN
        fx = 0.0
    if not fy > 0.0:
        fy = 0.0
    if fx > S.nx - 1:
        fx = S.nx - 1
    if fy > S.ny - 1:
        fy = S.ny - 1
    i = <int> fx
    j = <int> fy
    if i > S.nx - 2:
        i = S.nx - 2 if S.nx > 1 else 0
    if j > S.ny - 2:
        j = S.ny - 2 if S.ny > 1 else 0
    tx = fx - i
    ty = fy - j
    if S.nx == 1:
        return (1.0 - ty) * S.h[j] + ty * S.h[j + 1]
    if S.ny == 1:
        return (1.0 - tx) * S.h[i] + tx * S.h[i + 1]
    return ((1.0 - ty) * ((1.0 - tx) * S.h[j * S.nx + i] + tx * S.h[j * S.nx + i + 1])
            + ty * ((1.0 - tx) * S.h[(j + 1) * S.nx + i] + tx * S.h[(j + 1) * S.nx + i + 1]))
