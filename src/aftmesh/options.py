"""The keyword options of :func:`aftmesh.generate`, checked once at the door.

Every option is validated here, with a message naming it and the value given, before
any geometry is touched; the stages after this read a frozen :class:`Options`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._states import Order
from .aft import Strategy
from .errors import InvalidOptionError, InvalidSizeError

__all__ = [
    "DEFAULT_MIN_ANGLE",
    "MAX_MIN_ANGLE",
    "MAX_SMOOTH",
    "MAX_TRIANGLES",
    "ORDERS",
    "Options",
    "check_options",
]

# Get_next_edge's orders, as the kernel numbers them
ORDERS = {"shortest": Order.SHORTEST, "longest": Order.LONGEST, "oldest": Order.OLDEST}
# Smoothing stops by itself once nothing moves; a larger request is surely a mistake.
MAX_SMOOTH = 1000
# Kernel indices are int32: refuse a request for more triangles than that can number.
MAX_TRIANGLES = 2**30
# Default bound of the minimum-angle pass (degrees): Delaunay refinement is proven to
# terminate up to about 26.5 degrees and does so in practice up to about 33.8; 28 leaves
# a margin below that, and Basic_aft's meshes nearly meet it already (few points).
DEFAULT_MIN_ANGLE = 28.0
# Above this no Delaunay refinement is known to terminate in practice.
MAX_MIN_ANGLE = 34.0


@dataclass(frozen=True)
class Options:
    """The checked options of one generate call (see its docstring for each)."""

    order: str
    max_triangles: int | None
    min_area: float | None
    greedy: bool
    swaps: bool
    split_boundary: bool
    gradation: float
    close_factor: float
    smooth: int
    strategy: Strategy | None
    progress: Any
    slide_boundary: bool = True
    repair: bool = False
    tolerance: float = 0.0
    boundary_tags: Any = None
    min_angle: float = 0.0  # 0: no minimum-angle pass
    scaffold: bool = True  # plant the scaffold (scaffold.pxi) where it fits

    @property
    def slides(self) -> bool:
        """Whether smoothing slides the points that split input edges: greedy's mesh
        is the CDT of the discretized boundary itself."""
        return self.slide_boundary and self.split_boundary and not self.greedy

    @property
    def compiled(self) -> bool:
        """Whether the compiled loop runs (no subtask of the strategy overridden)."""
        return self.strategy is None or self.strategy.is_builtin

    @property
    def triangle_cap(self) -> tuple[int, str]:
        """The most triangles allowed, and how to name that limit in a message."""
        if self.max_triangles is None:
            return MAX_TRIANGLES, f"the limit of {MAX_TRIANGLES} triangles"
        return self.max_triangles, f"max_triangles={self.max_triangles}"


def real(name: str, value: Any, error: type[ValueError] = InvalidOptionError) -> float:
    """A finite real number from an option value, or an error naming the option."""
    if isinstance(value, (bool, np.bool_)) or isinstance(value, (str, bytes)):
        raise error(f"{name} must be a number, got {value!r}")
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise error(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(out):
        raise error(f"{name} must be finite, got {value!r}")
    return out


def _check_flags(flags: dict) -> None:
    for name, value in flags.items():
        if not isinstance(value, (bool, np.bool_)):
            raise InvalidOptionError(f"{name} must be True or False, got {value!r}")


def _check_max_triangles(max_triangles) -> int | None:
    if max_triangles is None:
        return None
    if isinstance(max_triangles, bool) or not isinstance(max_triangles, (int, np.integer)):
        raise InvalidOptionError(f"max_triangles must be an integer, got {max_triangles!r}")
    if max_triangles < 1:
        raise InvalidOptionError(f"max_triangles must be positive, got {max_triangles}")
    return min(int(max_triangles), MAX_TRIANGLES)


def _min_angle(value: float | None) -> float:
    """The bound of the minimum-angle pass in degrees, 0 for none."""
    if value is None:
        return 0.0
    out = real("min_angle", value)
    if out != 0 and not 0 < out <= MAX_MIN_ANGLE:
        raise InvalidOptionError(
            f"min_angle must be in (0, {MAX_MIN_ANGLE:g}] degrees (or 0 / None: no pass), "
            f"got {value!r}: Delaunay refinement is known to terminate only up to about "
            "33.8 degrees"
        )
    return out


def check_options(
    *,
    order: str,
    max_triangles: int | None,
    min_area: float | None,
    greedy: bool,
    swaps: bool,
    split_boundary: bool,
    gradation: float,
    close_factor: float,
    smooth: int,
    strategy: Strategy | None,
    progress: bool | Callable[..., object] | None,
    repair: bool = False,
    tolerance: float = 0.0,
    boundary_tags: Mapping[str, Any] | None = None,
    min_angle: float | None = None,
    scaffold: bool = True,
    slide_boundary: bool = True,
) -> Options:
    """Validate generate's keyword options; return them as an :class:`Options`."""
    _check_flags(
        dict(
            greedy=greedy,
            swaps=swaps,
            split_boundary=split_boundary,
            repair=repair,
            slide_boundary=slide_boundary,
        )
    )
    if not isinstance(order, str) or order not in ORDERS:
        raise InvalidOptionError(
            f"order={order!r} is not a valid option, must be one of {sorted(ORDERS)}"
        )
    max_triangles = _check_max_triangles(max_triangles)
    if min_area is not None and real("min_area", min_area) < 0:
        raise InvalidOptionError(f"min_area must be >= 0, got {min_area!r}")
    if not 0 <= real("close_factor", close_factor) < 2:
        raise InvalidOptionError(f"close_factor must be in [0, 2), got {close_factor!r}")
    if (
        isinstance(smooth, (bool, np.bool_))
        or not isinstance(smooth, (int, np.integer))
        or not 0 <= smooth <= MAX_SMOOTH
    ):
        raise InvalidOptionError(
            f"smooth must be a number of rounds from 0 to {MAX_SMOOTH}, got {smooth!r}"
        )
    if not (progress is None or isinstance(progress, (bool, np.bool_)) or callable(progress)):
        raise InvalidOptionError(
            f"progress must be True, False, None or a callable f(fraction), got {progress!r}"
        )
    if strategy is not None and not isinstance(strategy, Strategy):
        raise InvalidOptionError(
            f"strategy must be an aftmesh.aft.Strategy (or a subclass), got {strategy!r}"
        )
    gradation = real("gradation", gradation, InvalidSizeError)
    tolerance = real("tolerance", tolerance)
    if tolerance < 0:
        raise InvalidOptionError(f"tolerance must be >= 0, got {tolerance!r}")
    bound = _min_angle(min_angle)
    if not isinstance(scaffold, (bool, np.bool_)):
        raise InvalidOptionError(f"scaffold must be True or False, got {scaffold!r}")
    return Options(
        order=order,
        max_triangles=max_triangles,
        min_area=min_area,
        greedy=bool(greedy),
        swaps=bool(swaps),
        split_boundary=bool(split_boundary),
        gradation=gradation,
        close_factor=float(close_factor),
        smooth=int(smooth),
        slide_boundary=bool(slide_boundary),
        strategy=strategy,
        progress=progress,
        repair=bool(repair),
        tolerance=tolerance,
        boundary_tags=boundary_tags,
        min_angle=bound,
        scaffold=bool(scaffold),
    )
