"""Named boundary parts: ``generate(..., boundary_tags={name: selector})``.

A selector picks input edges (numbered as ``Mesh.segment_sources``): either a
callable ``f(x, y) -> bool array``, called once with the midpoints of all input edges
as two 1-D arrays, or a sequence of input-edge indices.  Tags are numbered 1, 2, ...
in the mapping's order (0: untagged); every output segment inherits the tag of the
input edge it lies on, so a side split into many pieces keeps its name.

>>> import numpy as np
>>> mids = np.array([[0.5, 0.0], [1.0, 0.5], [0.5, 1.0], [0.0, 0.5]])
>>> tags, names = resolve_boundary_tags({"left": lambda x, y: x == 0, "top": [2]}, mids)
>>> tags.tolist(), names
([0, 0, 2, 1], {'left': 1, 'top': 2})
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
import numpy.typing as npt

from .errors import InvalidOptionError

__all__ = ["resolve_boundary_tags", "segment_tags"]


def _select(name: str, selector, mids: np.ndarray) -> np.ndarray:
    """The input edges one selector picks, as a boolean array over the edges."""
    n = len(mids)
    if callable(selector):
        try:
            out = selector(np.ascontiguousarray(mids[:, 0]), np.ascontiguousarray(mids[:, 1]))
        except Exception as exc:
            raise InvalidOptionError(
                f"boundary_tags[{name!r}] raised {type(exc).__name__}: {exc}"
            ) from exc
        picked = np.asarray(out)
        if picked.ndim == 0:
            picked = np.full(n, bool(picked))
        if picked.shape != (n,) or picked.dtype != bool:
            raise InvalidOptionError(
                f"boundary_tags[{name!r}] must return a boolean array of length {n} (one "
                f"per input edge midpoint), got dtype {picked.dtype}, shape {picked.shape}"
            )
        return picked
    try:
        index = np.asarray(selector)
    except (TypeError, ValueError):
        index = None
    if (
        index is None
        or index.ndim != 1
        or not (index.size == 0 or np.issubdtype(index.dtype, np.integer))
    ):
        raise InvalidOptionError(
            f"boundary_tags[{name!r}] must be a callable f(x, y) or a sequence of "
            f"input-edge indices, got {selector!r}"
        )
    bad = (index < 0) | (index >= n)
    if bad.any():
        raise InvalidOptionError(
            f"boundary_tags[{name!r}] selects input edge {int(index[bad][0])}, but the "
            f"input edges are numbered 0..{n - 1}"
        )
    picked = np.zeros(n, dtype=bool)
    picked[index.astype(np.int64)] = True
    return picked


def resolve_boundary_tags(
    boundary_tags: Mapping[str, Any],
    edge_midpoints: npt.ArrayLike,
    describe: Callable[[int], str] | None = None,
) -> tuple[np.ndarray, dict[str, int]]:
    """(tag of each input edge (e,) int32, {name: tag}) from a boundary_tags mapping.

    ``describe(e)``, if given, names input edge e in messages.  An edge picked
    by two names raises InvalidOptionError naming both and the edge."""
    mids = np.asarray(edge_midpoints, dtype=np.float64).reshape(-1, 2)
    if not isinstance(boundary_tags, Mapping):
        raise InvalidOptionError(
            "boundary_tags must be a mapping {name: selector}, got "
            f"{type(boundary_tags).__name__}"
        )
    tags = np.zeros(len(mids), dtype=np.int32)
    names: dict[str, int] = {}
    for k, (name, selector) in enumerate(boundary_tags.items(), start=1):
        if not isinstance(name, str):
            raise InvalidOptionError(f"boundary_tags names must be strings, got {name!r}")
        picked = _select(name, selector, mids)
        clash = picked & (tags > 0)
        if clash.any():
            e = int(np.flatnonzero(clash)[0])
            other = next(n for n, t in names.items() if t == tags[e])
            what = f" ({describe(e)})" if describe is not None else ""
            raise InvalidOptionError(
                f"input edge {e}{what}, midpoint {mids[e].tolist()}, is selected by both "
                f"boundary_tags {other!r} and {name!r}: each edge gets one tag"
            )
        tags[picked] = k
        names[name] = k
    return tags, names


def segment_tags(edge_tags: np.ndarray, segment_sources: np.ndarray) -> np.ndarray:
    """The tag of each output segment: its input edge's tag, 0 where it has none."""
    src = np.asarray(segment_sources)
    if len(edge_tags) == 0:
        return np.zeros(len(src), dtype=np.int32)
    return np.where(src >= 0, edge_tags[np.maximum(src, 0)], 0).astype(np.int32)
