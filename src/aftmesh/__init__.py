"""aftmesh: 2D triangle meshes by the advancing-front technique on a constrained
Delaunay triangulation.

The main entry points are :func:`generate` (a quality mesh of a domain) and
:func:`cdt` (the constrained Delaunay triangulation of a planar straight-line graph).
"""
from .cdt import cdt
from .generate import generate
from .errors import (CrossingSegmentsError, InvalidDomainError, InvalidInputError,
                     InvalidOptionError, InvalidSizeError, KernelError)
from .mesh import Mesh
from .parallel import MeshingFailure, generate_many, imap_many
from .pvtu import read_partitioned

__version__ = "0.1.0"

__all__ = ["cdt", "generate", "generate_many", "imap_many", "MeshingFailure", "read_partitioned", "Mesh",
           "InvalidInputError", "InvalidDomainError", "CrossingSegmentsError", "InvalidSizeError", "InvalidOptionError", "KernelError"]
