"""aftmesh: 2D triangle meshes by the advancing-front technique on a constrained
Delaunay triangulation.

The main entry points are :func:`generate` (a quality mesh of a domain) and
:func:`cdt` (the constrained Delaunay triangulation of a planar straight-line graph).
"""

from ._version import __version__
from .cdt import cdt
from .errors import (
    CrossingSegmentsError,
    InvalidDomainError,
    InvalidInputError,
    InvalidOptionError,
    InvalidSizeError,
    KernelError,
)
from .generate import generate
from .mesh import Mesh
from .parallel import MeshingFailure, generate_many, imap_many
from .pvtu import read_partitioned

__all__ = [
    "__version__",
    "cdt",
    "generate",
    "Mesh",
    "generate_many",
    "imap_many",
    "MeshingFailure",
    "read_partitioned",
    "InvalidInputError",
    "InvalidDomainError",
    "CrossingSegmentsError",
    "InvalidSizeError",
    "InvalidOptionError",
    "KernelError",
]
