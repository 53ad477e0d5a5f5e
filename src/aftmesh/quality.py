"""Shape measures of triangles, shared by :class:`~aftmesh.mesh.Mesh` and the
pictures (:mod:`aftmesh.plotting`), which import it from here rather than from each
other."""

from __future__ import annotations

import numpy as np

__all__ = ["triangle_quality"]


def triangle_quality(points: np.ndarray, triangles: np.ndarray) -> dict[str, np.ndarray]:
    """Per-triangle shape measures.

    Returns a dict of arrays: ``radius_ratio`` (2 r_in / r_circ: 1 for an equilateral
    triangle, 0 for a degenerate one), ``min_angle`` and ``max_angle`` in degrees,
    ``angles`` (t, 3) in degrees with column k the angle at vertex k, ``area``, and
    ``edge_lengths`` (t, 3) with column k the edge opposite vertex k.
    """
    p = points[triangles]
    e = np.stack([p[:, 2] - p[:, 1], p[:, 0] - p[:, 2], p[:, 1] - p[:, 0]], axis=1)
    lengths = np.linalg.norm(e, axis=2)
    a, b, c = lengths[:, 0], lengths[:, 1], lengths[:, 2]
    area = 0.5 * (e[:, 2, 0] * (-e[:, 1, 1]) - e[:, 2, 1] * (-e[:, 1, 0]))
    perimeter = a + b + c
    with np.errstate(divide="ignore", invalid="ignore"):
        # 2 r_in / r_circ = 16 area^2 / (perimeter a b c)
        rr = np.where(area > 0, 16.0 * area * area / (perimeter * a * b * c), 0.0)
        cos = np.stack(
            [
                (b * b + c * c - a * a) / (2 * b * c),
                (c * c + a * a - b * b) / (2 * c * a),
                (a * a + b * b - c * c) / (2 * a * b),
            ],
            axis=1,
        )
    ang = np.degrees(np.arccos(np.clip(np.nan_to_num(cos, nan=1.0), -1.0, 1.0)))
    return dict(
        radius_ratio=rr,
        min_angle=ang.min(axis=1),
        max_angle=ang.max(axis=1),
        angles=ang,
        area=area,
        edge_lengths=lengths,
    )
