"""Basic_aft (Figure 5 of the paper) in Python, with pluggable subtasks.

The loop below reads like the paper's Figure 5 and calls the kernel's primitives.  A
:class:`Strategy` supplies the five subtasks a user may replace (Get_next_edge,
Compute_new_candidate, New_is_preferred and its proximity rule ``is_crowded``,
Mesh_size_constraint); the kernel supplies the ones that keep the frontal edge set
and the CDT consistent (Compute_existing_candidate, Check_visible, Update_internal,
Update_boundary, Add_triangle).  When no subtask is overridden,
:func:`aftmesh.generate` runs the same algorithm as one compiled loop without the GIL
instead; both give the identical mesh.

In the CDT representation R can be refused but not forced: Check_visible answers
"not visible" unless S lies outside the circumcircle of T(E, R) (Lemma 3.1), the
condition under which checking visibility from the midpoint of E is enough and T(E, R)
is a triangle of the unmeshed region's CDT once R is inserted.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ._kernel import Triangulation

__all__ = ["Strategy", "basic_aft"]


class Strategy:
    """The built-in subtasks.  Subclass and override any of the five methods.

    Each method receives the kernel (``aftmesh._kernel.Triangulation``) and the current
    edge E as a half-edge index; ``kernel.edge(E)`` gives its end vertices and
    ``kernel.vertex(v)`` a vertex's coordinates.
    """

    def get_next_edge(self, kernel: Triangulation) -> int:
        """Any front edge (minimal requirement); -1 when the front is empty.
        Built in: the kernel's queue (shortest, longest or oldest first)."""
        return kernel.get_next_edge()

    def compute_new_candidate(self, kernel: Triangulation, E: int) -> tuple[float, float, float]:
        """A point R on the left of E, and the length h the proximity rules measure
        against (the local size, adjusted as generate's ``close_factor`` describes):
        (x, y, h)."""
        return kernel.compute_new_candidate(E)

    def new_is_preferred(
        self, kernel: Triangulation, E: int, R: tuple[float, float], S: int, h: float
    ) -> bool:
        """Whether to try R rather than the existing candidate S (must be false when
        they coincide)."""
        return kernel.new_is_preferred(E, R[0], R[1], S, h)

    def mesh_size_constraint(self, kernel: Triangulation, E: int, R: tuple[float, float]) -> bool:
        """True to refuse a new vertex now (formulas (4) and (5))."""
        return kernel.mesh_size_constraint(E, R[0], R[1])

    def is_crowded(self, kernel: Triangulation, E: int, R: tuple[float, float], h: float) -> bool:
        """New_is_preferred's proximity rule, asked once Check_visible has located R."""
        return kernel.is_crowded(E, R[0], R[1], h)

    @property
    def is_builtin(self) -> bool:
        """True when no subtask is overridden (the compiled loop can run instead)."""
        names = (
            "get_next_edge",
            "compute_new_candidate",
            "new_is_preferred",
            "mesh_size_constraint",
            "is_crowded",
        )
        return all(getattr(type(self), n) is getattr(Strategy, n) for n in names)


def basic_aft(kernel: Triangulation, strategy: Strategy) -> None:
    """Run Basic_aft on a kernel whose domain CDT is built (every domain triangle
    unmeshed) and whose size field and options are set.

    The built-in Compute_new_candidate may move R onto the lattice of converging rows
    (``cython_ext/lattice.pxi``); when that point is refused, the point it computed
    before the move is judged before S is taken, as in the compiled loop."""
    kernel.convert_to_frontal_edge_set()
    builtin_candidate = type(strategy).compute_new_candidate is Strategy.compute_new_candidate
    while True:
        E = strategy.get_next_edge(kernel)
        if E < 0:
            break
        rx, ry, h = strategy.compute_new_candidate(kernel, E)
        S = kernel.compute_existing_candidate(E)
        new = _r_is_taken(kernel, strategy, E, (rx, ry), S, h)
        plain = kernel.candidate_off_lattice() if builtin_candidate else None
        if not new and plain is not None:
            rx, ry = plain
            new = _r_is_taken(kernel, strategy, E, (rx, ry), S, h)
        if new:
            t = kernel.update_internal(E, rx, ry)
        else:
            t = kernel.update_boundary(E)
        kernel.add_triangle(t)


def _r_is_taken(
    kernel: Triangulation, strategy: Strategy, E: int, R: tuple[float, float], S: int, h: float
) -> bool:
    """New_is_preferred and Mesh_size_constraint, then Check_visible and the proximity
    rule: whether T(E, R) is made rather than T(E, S)."""
    if not strategy.new_is_preferred(kernel, E, R, S, h):
        return False
    if strategy.mesh_size_constraint(kernel, E, R):
        return False
    visible, _left, _right = kernel.check_visible(E, R[0], R[1])
    return bool(visible) and not strategy.is_crowded(kernel, E, R, h)
