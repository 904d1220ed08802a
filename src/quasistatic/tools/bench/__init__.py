"""Benchmarks: speed, accuracy and scale of every method against baselines measured in the same run.

Run them with ``quasistatic bench`` (or ``python -m benchmarks`` from the
repository). :func:`run_benchmarks` returns a :class:`BenchResult`;
:func:`render_result`, :func:`write_results` and :func:`write_scaling_plot`
print and save it. The problem families live in :data:`FAMILIES`.
"""

from .families import FAMILIES, Family
from .output import markdown_tables, render_result, write_results, write_scaling_plot
from .pipeline import PipelineRow
from .runner import BatchRow, BenchConfig, BenchResult, Row, growth_exponents, machine_info, run_benchmarks
from .sweep_bench import SweepRow, run_sweep_bench

__all__ = [
    "FAMILIES",
    "BatchRow",
    "BenchConfig",
    "BenchResult",
    "Family",
    "PipelineRow",
    "Row",
    "SweepRow",
    "growth_exponents",
    "machine_info",
    "markdown_tables",
    "render_result",
    "run_benchmarks",
    "run_sweep_bench",
    "write_results",
    "write_scaling_plot",
]
