"""Pictures of meshes with matplotlib (``pip install aftmesh[plot]``).

matplotlib is imported inside the functions, so ``import aftmesh`` never needs it.
"""

from __future__ import annotations

from os import PathLike
from typing import TYPE_CHECKING, Any

import numpy as np

from .errors import InvalidOptionError
from .quality import triangle_quality

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.colors import Colormap
    from matplotlib.typing import ColorType

    from .mesh import Mesh

__all__ = ["plot_mesh", "save_png"]

_COLOR_BY = ("quality", "region", "none")


def _import_matplotlib(what: str):
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise ModuleNotFoundError(
            f"{what} needs matplotlib: pip install aftmesh[plot]", name="matplotlib"
        ) from None


def plot_mesh(
    mesh: Mesh,
    ax: Axes | None = None,
    color_by: str = "quality",
    show_segments: bool = True,
    *,
    cmap: str | Colormap | None = None,
    edge_color: ColorType = "0.2",
    edge_width: float | None = None,
    segment_color: ColorType = "k",
    segment_width: float = 1.5,
    colorbar: bool = True,
    title: str | bool = True,
    **kwargs: Any,
) -> Axes:
    """Draw a mesh: filled triangles, thin edges, the segments thicker.

    Parameters
    ----------
    mesh : aftmesh.Mesh
    ax : matplotlib Axes, optional
        Where to draw; by default a new figure's axes (through pyplot).
    color_by : {'quality', 'region', 'none'}
        Fill each triangle by its radius ratio (2 r_in / r_circ, 1 = equilateral) on a
        fixed [0, 1] scale, by its region (one color per region), or leave it white.
    show_segments : bool
        Draw the constrained edges (boundary, interfaces) on top.
    cmap : str or Colormap, optional
        Colormap of the fill (default 'viridis' for quality; for regions a light
        qualitative map with a color per region).
    edge_color, edge_width
        Color and line width of the triangle edges; the width defaults to one that
        shrinks as the mesh grows (``edge_width=0`` hides the edges).
    segment_color, segment_width
        Color and line width of the segments.
    colorbar : bool
        Add a colorbar for 'quality' and 'region'.
    title : str or bool
        True: a title with the counts and the smallest angle; False: none; a string:
        that title.
    **kwargs
        Passed on to ``Axes.tripcolor`` (e.g. ``alpha``, ``rasterized``).

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import aftmesh
    >>> from matplotlib.figure import Figure
    >>> mesh = aftmesh.generate([(0, 0), (2, 0), (2, 1), (0, 1)], size=0.25)
    >>> ax = plot_mesh(mesh, ax=Figure().add_subplot())
    >>> ax.get_title().split(",")[0] == f"{mesh.n_triangles} triangles"
    True
    """
    if color_by not in _COLOR_BY:
        raise InvalidOptionError(
            f"color_by={color_by!r} is not a valid option, must be one of {list(_COLOR_BY)}"
        )
    _import_matplotlib("plotting a mesh")
    from matplotlib.collections import LineCollection
    from matplotlib.colors import BoundaryNorm, Normalize

    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots()
    P, T = mesh.points, mesh.triangles
    fig = ax.figure
    if edge_width is None:
        # edges of a 100k-triangle mesh at 0.5 pt would paint the picture grey
        edge_width = float(np.clip(12.0 / np.sqrt(max(len(T), 1)), 0.05, 0.6))
    q = triangle_quality(P, T) if len(T) else None
    if len(T):
        edge_style: dict[str, Any] = dict(
            edgecolors=edge_color if edge_width > 0 else "none", linewidth=edge_width
        )
        if color_by == "quality":
            assert q is not None
            art = ax.tripcolor(
                P[:, 0],
                P[:, 1],
                T,
                facecolors=q["radius_ratio"],
                cmap=cmap or "viridis",
                norm=Normalize(0.0, 1.0),
                **edge_style,
                **kwargs,
            )
            if colorbar:
                fig.colorbar(art, ax=ax, shrink=0.8, label="radius ratio (1 = equilateral)")
        elif color_by == "region":
            values, index = np.unique(mesh.regions, return_inverse=True)
            k = len(values)
            # light qualitative colors keep the edges visible on top of them
            cmap = cmap or (
                "Pastel1" if k <= 9 else "Set3" if k <= 12 else "tab20" if k <= 20 else "turbo"
            )
            # one color per region, whatever the region numbers are (qualitative maps
            # take the first k colors, longer maps are spread over the k regions)
            ncolors = k if k <= 20 else 256
            art = ax.tripcolor(
                P[:, 0],
                P[:, 1],
                T,
                facecolors=index.astype(float),
                cmap=cmap,
                norm=BoundaryNorm(np.arange(k + 1) - 0.5, ncolors),
                **edge_style,
                **kwargs,
            )
            if colorbar:
                bar = fig.colorbar(art, ax=ax, shrink=0.8, label="region", ticks=np.arange(k))
                bar.ax.set_yticklabels([str(v) for v in values])
        else:
            ax.tripcolor(
                P[:, 0],
                P[:, 1],
                T,
                facecolors=np.zeros(len(T)),
                cmap="Greys",
                norm=Normalize(0.0, 1.0),
                **edge_style,
                **kwargs,
            )
    if show_segments and len(mesh.segments):
        ax.add_collection(
            LineCollection(
                P[mesh.segments], colors=segment_color, linewidths=segment_width, zorder=3
            )
        )
    ax.set_aspect("equal")
    if len(P):
        lo, hi = P.min(axis=0), P.max(axis=0)
        pad = 0.02 * float(max(hi - lo))
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
    if title is True:
        text = f"{mesh.n_triangles} triangles, {mesh.n_points} points"
        if q is not None:
            text += f", min angle {q['min_angle'].min():.1f}\N{DEGREE SIGN}"
        ax.set_title(text)
    elif title:
        ax.set_title(str(title))
    return ax


def save_png(
    mesh: Mesh,
    path: str | PathLike,
    *,
    dpi: int = 150,
    figsize: tuple[float, float] | None = None,
    zoom: tuple[float, float, float, float] | None = None,
    **kwargs: Any,
) -> None:
    """Draw a mesh with :func:`plot_mesh` into a PNG file.

    Uses a standalone matplotlib ``Figure`` (no pyplot, no window, no global state),
    so it works without a display and in loops.

    Parameters
    ----------
    mesh : aftmesh.Mesh
    path : str or path-like
    dpi : int
    figsize : (width, height) in inches, optional
        By default 8 inches wide, the height following the mesh's aspect ratio.
    zoom : (xmin, xmax, ymin, ymax), optional
        Add a second panel below the whole mesh: a close-up of that window.
    **kwargs
        Passed to :func:`plot_mesh` (``color_by``, ``show_segments``, ``title``, ...).

    Examples
    --------
    >>> import aftmesh, tempfile, os
    >>> mesh = aftmesh.generate([(0, 0), (1, 0), (1, 1), (0, 1)], size=0.2)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     save_png(mesh, os.path.join(tmp, "square.png"), dpi=50, zoom=(0, 0.3, 0, 0.3))
    ...     os.listdir(tmp)
    ['square.png']
    """
    _import_matplotlib("saving a PNG")
    from matplotlib.figure import Figure

    if zoom is not None:
        bad_zoom = InvalidOptionError(f"zoom must be (xmin, xmax, ymin, ymax), got {zoom!r}")
        try:
            x0, x1, y0, y1 = (float(v) for v in zoom)
        except (TypeError, ValueError):
            raise bad_zoom from None
        if not (x0 < x1 and y0 < y1):
            raise bad_zoom
    panels = (
        [(mesh.points.min(axis=0), mesh.points.max(axis=0))]
        if len(mesh.points)
        else [(np.zeros(2), np.ones(2))]
    )
    if zoom is not None:
        panels.append((np.array([x0, y0]), np.array([x1, y1])))
    if figsize is None:
        # 8 inches wide; each panel as high as its aspect ratio asks, plus room for
        # its title and ticks
        height = 0.0
        for lo, hi in panels:
            span = hi - lo
            aspect = float(span[1] / span[0]) if span[0] > 0 else 1.0
            height += float(np.clip(8.0 * aspect * 0.85 + 0.9, 2.5, 12.0))
        figsize = (8.0, height)
    fig = Figure(figsize=figsize, layout="constrained")
    axes = fig.subplots(len(panels), 1, squeeze=False)[:, 0]
    plot_mesh(mesh, ax=axes[0], **kwargs)
    if zoom is not None:
        close = dict(kwargs, colorbar=False, title="close-up")
        plot_mesh(mesh, ax=axes[1], **close)
        axes[1].set_xlim(x0, x1)
        axes[1].set_ylim(y0, y1)
    fig.savefig(path, dpi=dpi)
