"""Type aliases shared by the annotations of the public functions (for mypy and
readers; nothing here runs any check)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from os import PathLike
from typing import Any

import numpy as np
import numpy.typing as npt

# A file name: anything ``pathlib.Path`` accepts.
PathArg = str | PathLike[str]

# A domain in any accepted form (shapely geometry, sequence of polygons, (n, 2)
# coordinates, Triangle-style dict, .poly path): checked at run time by to_domain,
# so its static type is open.
DomainArg = Any

# ``f(x, y)``: two 1-D float arrays of equal length in, one size per point (or a
# single number) out.
SizeFunction = Callable[[npt.NDArray[np.float64], npt.NDArray[np.float64]], npt.ArrayLike]

# The ``size`` argument: a number, a size function, one number per region, or None.
SizeArg = float | SizeFunction | Sequence[float] | None

# A point (x, y): an array or a pair of numbers.
Point2 = npt.NDArray[np.float64] | Sequence[float]
