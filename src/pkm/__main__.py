"""``python -m pkm ...``: the ``pkm`` command line (see :mod:`pkm.cli`)."""

from pkm.cli import main

raise SystemExit(main())
