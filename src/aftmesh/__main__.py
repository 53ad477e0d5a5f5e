"""``python -m aftmesh``: the same as the ``aftmesh`` command (see :mod:`aftmesh.cli`)."""

from .cli import main

raise SystemExit(main())
