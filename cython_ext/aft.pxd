# The state of the compiled Basic_aft loop (routines in front.pxi, smoothing.pxi):
# the queue of Get_next_edge, the options, the counters and Check_visible's output.
from libc.stdint cimport int32_t, int64_t, uint8_t
from cpython.ref cimport PyObject

from sizing cimport SizeField

cdef struct QueueItem:
    int32_t he          # the half-edge when pushed (it may move; org/dst identify it)
    int32_t org
    int32_t dst
    int32_t next        # the next item of its length class, oldest first (-1: last)

cdef struct Aft:
    # Get_next_edge's queue: one first-in first-out list per length class, the items
    # in a pool with a free list (front.pxi)
    QueueItem* items
    int32_t* head       # per class: the oldest item, or -1
    int32_t* tail       # per class: the newest item, or -1
    int queue_n          # items queued
    int items_n, items_cap, free_item
    int low_class       # no class below this one holds an item
    # the initial front (the edges on the input segments), in the queue's order, taken
    # before any queued edge: first[first_pos:first_n] are still to come (front.pxi)
    QueueItem* first
    int first_n, first_pos
    int used_low, used_high     # the classes used since the queue was last emptied
    int order
    SizeField size
    int64_t max_triangles   # N_max of formula (4); < 0: none
    double min_area         # A_min of formula (5); <= 0: none
    double close_factor     # New_is_preferred takes S when |S - R| < close_factor * h
    bint swaps              # Add_triangle keeps the meshed region a CDT by edge swaps
    bint greedy             # New_is_preferred is always false
    int32_t nv_input        # vertices of the domain's CDT (below: input vertices)
    int64_t n_meshed        # N(T)
    int64_t n_unmeshed      # triangles of the unmeshed CDT
    int64_t n_new           # vertices created by Update_internal
    int64_t n_steps         # passes through the while loop
    int64_t n_forced        # Update_internal calls that needed Cline-Renka for F, G
    int64_t n_split         # points smoothing's valence splits added (valence.pxi)
    # scaffold vertices (scaffold.pxi): vertices scaffold_lo..scaffold_hi of the
    # unmeshed CDT, scaffold_alive[v - scaffold_lo] while v is one (n_scaffold of them)
    bint scaffold_on        # plant them (set_options decides)
    int32_t scaffold_lo, scaffold_hi
    uint8_t* scaffold_alive
    int64_t n_scaffold
    int64_t n_scaffold_planted
    int64_t n_scaffold_kept     # could not be removed: ordinary vertices of the mesh
    int32_t crowd_scaffold  # the scaffold vertex is_crowded found too near R
    # converging rows' lattice (lattice.pxi): whether rows may snap to it, whether it
    # is the lattice of a size field's plateau, its origin and the direction of its
    # rows, whether the last Compute_new_candidate moved R onto it and R before the
    # move, the front's curvature at each vertex (one constant size) and each vertex's
    # row from the boundary (a plateau)
    bint lat_on
    bint lat_plateau
    double lat_o[2]
    double lat_dir[2]
    bint lat_moved
    double lat_plain[2]
    double* vkappa
    int32_t vkappa_cap
    int32_t* vrow
    int32_t vrow_cap
    # Check_visible's output: crossed edges of the line of sight, and where R lies
    int32_t* left
    int32_t* right
    int nleft, nright, lr_cap
    int vis_loc, vis_where
    # progress: meshed / total area, reported to a Python callable (a borrowed
    # reference kept alive by the owning Triangulation) every few thousand steps
    double area_total, area_meshed
    void* progress
    # whether the thread running the loops is Python's main thread: only there can a
    # signal handler run (elsewhere PyErr_CheckSignals does nothing), so elsewhere the
    # loops never take the GIL back to ask
    bint signals_here
    # the exception a signal handler raised (Ctrl-C's KeyboardInterrupt, a watchdog's
    # own exception), held here until the def layer can raise it again
    PyObject* exc_type
    PyObject* exc_value
    PyObject* exc_tb
