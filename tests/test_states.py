"""The Python enums of aftmesh._states hold the kernel's own values."""

import pytest

from aftmesh import _kernel
from aftmesh._states import EdgeFlag, Location, Order, TriangleState


@pytest.mark.parametrize(
    "enum, values",
    [
        (TriangleState, _kernel.TRIANGLE_STATE_VALUES),
        (Order, _kernel.ORDER_VALUES),
        (Location, _kernel.LOCATION_VALUES),
        (EdgeFlag, _kernel.EDGE_FLAG_VALUES),
    ],
)
def test_python_enum_matches_kernel_enum(enum, values):
    assert {m.name: int(m) for m in enum} == values


def test_state_at_reports_the_kernel_state_of_a_point():
    import numpy as np

    square = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=float)
    k = _kernel.Triangulation(square)
    k.insert_points(np.arange(4, dtype=np.int32))
    k.insert_segments(np.array([(0, 1), (1, 2), (2, 3), (3, 0)], dtype=np.int32))
    k.carve(np.zeros((0, 2)), True)
    assert k.state_at(0.5, 0.25) == TriangleState.UNMESHED
    assert k.state_at(2.0, 0.5) == TriangleState.EXTERIOR
    assert k.state_at(0.5, 0.0) is None  # on a segment: no single region
