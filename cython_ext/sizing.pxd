# The compiled size field's storage (routines in sizing.pxi).

cdef struct SizeField:
    double x0, y0       # lower-left grid node
    double dx, dy       # node spacing
    int nx, ny          # nodes per row / per column
    double* h           # h[j * nx + i] at (x0 + i dx, y0 + j dy)
