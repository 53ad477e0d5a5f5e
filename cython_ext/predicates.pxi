# Temporary naive predicates (being replaced by the exact implementation).
cdef inline int orient2d(const double* a, const double* b, const double* c) noexcept nogil:
    cdef double det = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    return (det > 0) - (det < 0)

cdef inline int incircle(const double* a, const double* b, const double* c, const double* d) noexcept nogil:
    cdef double adx = a[0] - d[0], ady = a[1] - d[1]
    cdef double bdx = b[0] - d[0], bdy = b[1] - d[1]
    cdef double cdx = c[0] - d[0], cdy = c[1] - d[1]
    cdef double det = ((adx * adx + ady * ady) * (bdx * cdy - cdx * bdy)
                       + (bdx * bdx + bdy * bdy) * (cdx * ady - adx * cdy)
                       + (cdx * cdx + cdy * cdy) * (adx * bdy - bdx * ady))
    return (det > 0) - (det < 0)

def py_orient2d(double ax, double ay, double bx, double by, double cx, double cy):
    cdef double p[6]
    p[0] = ax; p[1] = ay; p[2] = bx; p[3] = by; p[4] = cx; p[5] = cy
    return orient2d(&p[0], &p[2], &p[4])

def py_incircle(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy):
    cdef double p[8]
    p[0] = ax; p[1] = ay; p[2] = bx; p[3] = by; p[4] = cx; p[5] = cy; p[6] = dx; p[7] = dy
    return incircle(&p[0], &p[2], &p[4], &p[6])
