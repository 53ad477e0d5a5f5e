# The compiled size field: target edge length h(x, y) read by Compute_new_candidate.
#
# A background grid of nx * ny nodes over a rectangle, interpolated bilinearly and
# clamped outside it; a 1 x 1 grid is a constant.  The Python layer fills the grid by
# sampling the user's size (a number or a callable evaluated on whole arrays at once),
# so the compiled loop never calls back into Python.
#
# Uses: sizing.pxd (SizeField); nothing else of the kernel.

from libc.math cimport sqrt
from sizing cimport SizeField


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


cdef void limit_gradation(double* h, Py_ssize_t nx, Py_ssize_t ny, double dx, double dy,
                          double rate, int rounds) noexcept nogil:
    """In place on the ny x nx grid h (row j at h + j nx): lower h so that h[p] <=
    h[q] + rate |p - q| between 8-neighbours, by raster sweeps forward then backward,
    `rounds` times: the size then grows by at most `rate` per unit of length along any
    path of grid nodes (the gradation limit of src/aftmesh/sizing.py)."""
    cdef Py_ssize_t i, j
    cdef int r
    cdef double cx = rate * dx, cy = rate * dy, cd = rate * sqrt(dx * dx + dy * dy), v
    for r in range(rounds):
        for j in range(ny):
            for i in range(nx):
                v = h[j * nx + i]
                if i > 0:
                    v = min(v, h[j * nx + i - 1] + cx)
                if j > 0:
                    v = min(v, h[(j - 1) * nx + i] + cy)
                    if i > 0:
                        v = min(v, h[(j - 1) * nx + i - 1] + cd)
                    if i < nx - 1:
                        v = min(v, h[(j - 1) * nx + i + 1] + cd)
                h[j * nx + i] = v
        for j in range(ny - 1, -1, -1):
            for i in range(nx - 1, -1, -1):
                v = h[j * nx + i]
                if i < nx - 1:
                    v = min(v, h[j * nx + i + 1] + cx)
                if j < ny - 1:
                    v = min(v, h[(j + 1) * nx + i] + cy)
                    if i < nx - 1:
                        v = min(v, h[(j + 1) * nx + i + 1] + cd)
                    if i > 0:
                        v = min(v, h[(j + 1) * nx + i - 1] + cd)
                h[j * nx + i] = v
