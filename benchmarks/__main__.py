"""``python -m benchmarks ...`` is ``quasistatic bench ...``."""

import sys

from quasistatic.cli import app

if __name__ == "__main__":
    app(["bench", *sys.argv[1:]], prog_name="python -m benchmarks")
