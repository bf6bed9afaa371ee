"""``python -m discsim``: the command line (see :mod:`discsim.cli`)."""

from discsim.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
