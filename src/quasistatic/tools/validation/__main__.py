"""Command line of the validation suite: ``python -m quasistatic.tools.validation [--folder F] [--quick] [--whitney PNG]``."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

from .. import validation
from .cases import DEFAULT_FOLDER
from .report import render_results
from .run import run_validation
from .whitney import plot_whitney


def main(argv: Sequence[str] | None = None) -> int:
    """Run the suite and print the table, or draw Whitney's diagram with ``--whitney``.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments after the program name; ``sys.argv[1:]`` by default.

    Returns
    -------
    int
        The exit status: 0 when every case is ``pass`` or ``known``, else 1.
    """
    parser = argparse.ArgumentParser(prog="python -m quasistatic.tools.validation", description=(validation.__doc__ or "").splitlines()[0])
    parser.add_argument("--folder", type=Path, default=DEFAULT_FOLDER, help="validation folder (default: ./validation)")
    parser.add_argument("--quick", action="store_true", help="leave out the slow cases (3-D runs, sweeps)")
    parser.add_argument("--whitney", type=Path, metavar="PNG", help="draw Whitney's jamming diagram (a qs.sweep) to PNG and exit")
    parser.add_argument("--jobs", type=int, default=1, help="worker processes for the --whitney sweep (default 1)")
    args = parser.parse_args(argv)
    if args.whitney is not None:
        print(f"wrote {plot_whitney(args.whitney, args.folder, jobs=args.jobs)}")
        return 0
    results = run_validation(args.folder, include_slow=not args.quick)
    render_results(results)
    return 0 if all(r.ok for r in results) else 1


if __name__ == "__main__":
    raise SystemExit(main())
