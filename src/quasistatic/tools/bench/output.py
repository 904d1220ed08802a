"""Benchmark output: a rich table on the terminal, results.csv / results.json, and a log-log scaling plot."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table

from .pipeline import growth_exponent
from .runner import BenchResult, Row, format_seconds, format_seconds_range, growth_exponents

__all__ = ["render_result", "write_results", "write_scaling_plot", "markdown_tables", "SCALING_FAMILIES"]

SCALING_FAMILIES = ("box-push-nf", "pile-nf", "box-push", "pile")
_CSV_FIELDS = (
    "family",
    "size",
    "size_label",
    "contacts",
    "bodies",
    "method",
    "baseline",
    "skipped",
    "instances",
    "samples",
    "median",
    "p25",
    "p75",
    "ratio",
    "assemble",
    "statuses",
    "worst_residual",
    "agree",
    "compared",
    "note",
)


def render_result(result: BenchResult, console: Console) -> None:
    """The table (one row per family, size and method), the batch throughput and the growth exponents."""
    table = Table(
        title="quasistatic benchmarks: warm solves, median over repeats (times per solve)",
        caption="ratio = baseline median / method median (> 1 is faster), baseline in the same run: "
        "scip (frictional) or lp (frictionless); agree = same status (and twist for solved) as the baseline",
        show_lines=False,
    )
    for name, justify, wrap in (
        ("family", "left", False),
        ("size", "right", False),
        ("m", "right", False),
        ("method", "left", False),
        ("median", "right", False),
        ("IQR", "right", False),
        ("ratio", "right", False),
        ("statuses", "left", True),
        ("residual", "right", False),
        ("agree", "right", False),
    ):
        table.add_column(name, justify=justify, no_wrap=not wrap)  # type: ignore[arg-type]
    previous = None
    for row in result.rows:
        key = (row.family, row.size)
        if key != previous:
            if previous is not None and key[0] != previous[0]:
                table.add_section()
            table.add_row(row.family, str(row.size), str(row.contacts), "[dim](assemble)[/dim]", format_seconds(row.assemble))
            previous = key
        if row.skipped:
            table.add_row("", "", "", row.method, "skipped", "", "", f"[dim]{row.skipped}[/dim]")
            continue
        table.add_row(
            "",
            "",
            "",
            row.method,
            format_seconds(row.median),
            format_seconds_range(row.p25, row.p75),
            "-" if row.ratio is None else f"{row.ratio:.3g}",
            _statuses(row),
            "-" if row.worst_residual is None else f"{row.worst_residual:.1e}",
            _agreement(row),
        )
    console.print(table)
    if result.left_out:
        console.print(f"not in this run: {', '.join(result.left_out)}")
    if result.batch:
        batch = Table(title="solve_many throughput (small 2-D scenes, pre-assembled)")
        for name in ("scenes", "method", "n_jobs", "problems", "solves/s", "statuses", "same as n_jobs=1"):
            batch.add_column(name)
        for b in result.batch:
            if b.skipped:
                batch.add_row(b.scenes, b.method, "-", str(b.problems), f"skipped ({b.skipped})", "", "")
                continue
            same = "-" if b.matches_serial is None else ("yes" if b.matches_serial else "NO")
            batch.add_row(b.scenes, b.method, str(b.n_jobs), str(b.problems), f"{b.per_second:,.0f}", _counts(b.statuses), same)
        console.print(batch)
    if result.sweeps:
        console.print(_sweep_table(result))
    if result.pipeline:
        console.print(_pipeline_table(result))
        console.print(_detect_growth(growth_exponent(list(result.pipeline))))
    growth = growth_exponents(result.rows)
    for family in SCALING_FAMILIES:
        if family in growth:
            slopes = ", ".join(f"{m} n^{s:.2f}" for m, s in growth[family].items())
            console.print(f"growth of the median with contacts, {family}: {slopes}")
    m = result.machine
    console.print(
        f"machine: {m['cores']} cores, {m['cpu']}, Python {m['python']}, load average {m.get('load_average_at_start')} "
        f"at start, effective cores for 2 workers {m.get('effective_cores_for_2_workers', '-')}, "
        f"BLAS threads {m.get('blas_threads', 'not held')} while timing; "
        f"run took {result.wall_seconds:.0f} s"
    )


_PIPELINE_COLUMNS = ("case", "objects", "pairs", "near", "contacts", "median", "IQR", "CPU median", "ratio", "answer", "note")


def _pipeline_cells(row: dict[str, Any]) -> list[str]:
    """One robots-and-geometry row as text cells, from ``PipelineRow.to_dict()``."""
    if row["skipped"]:
        return [row["case"], "", "", "", "", "skipped", "", "", "", row["skipped"], ""]
    answer = f"{row['status']}, certified {'yes' if row['certified'] else 'no'}" if row["status"] else ""
    return [
        row["case"],
        str(row["objects"]),
        str(row["pairs"]),
        str(row["near"]),
        str(row["contacts"]),
        format_seconds(row["median"]),
        format_seconds_range(row["p25"], row["p75"]),
        "-" if row.get("cpu_median") is None else format_seconds(row["cpu_median"]),
        "-" if row["ratio"] is None else f"{row['ratio']:.3g}",
        answer,
        row["note"],
    ]


_PIPELINE_CAPTION = (
    "pairs: after the broad phase; near: left to coal (one side a free body); ratio: baseline / row median; "
    "CPU median: the same calls' process time (less inflated by other work on a shared machine)"
)


def _detect_growth(slope: float | None) -> str:
    return "" if slope is None else f"growth of World.detect time with near pairs: n^{slope:.2f}"


def _pipeline_table(result: BenchResult) -> Table:
    table = Table(title="robots and geometry: joint positions to contacts, Jacobians and answers", caption=_PIPELINE_CAPTION)
    for name in _PIPELINE_COLUMNS[:-1]:  # the notes (what each row times) are in results.md and results.json
        table.add_column(name, no_wrap=name != "answer")
    for row in result.pipeline:
        table.add_row(*_pipeline_cells(row.to_dict())[:-1])
    return table


def _statuses(row: Row) -> str:
    text = _counts(row.statuses)
    return f"{text} ({row.note})" if row.note else text


def _counts(statuses: dict[str, int]) -> str:
    return ", ".join(f"{k} {v}" for k, v in sorted(statuses.items()))


def _agreement(row: Row) -> str:
    if row.method == row.baseline:
        return "ref"
    if row.compared == 0:
        return "n/a"
    return f"{row.agree}/{row.compared}"


def markdown_tables(data: dict[str, Any]) -> str:
    """The results (``BenchResult.to_dict()`` or a loaded ``results.json``) as Markdown tables."""
    lines = [
        "| family | size | m | method | median | IQR | ratio | statuses | residual | agree |",
        "| --- | ---: | ---: | --- | ---: | ---: | ---: | --- | ---: | ---: |",
    ]
    previous = None
    for row in data["rows"]:
        key = (row["family"], row["size"])
        if key != previous:
            lines.append(
                f"| **{row['family']}** | {row['size']} | {row['contacts']} | (assemble) | {format_seconds(row['assemble'])} | | | | | |"
            )
            previous = key
        if row["skipped"]:
            lines.append(f"| | | | {row['method']} | skipped | | | {row['skipped']} | | |")
            continue
        statuses = _counts(row["statuses"]) + (f" ({row['note']})" if row["note"] else "")
        ratio = "-" if row["ratio"] is None else f"{row['ratio']:.3g}"
        residual = "-" if row["worst_residual"] is None else f"{row['worst_residual']:.1e}"
        agree = "ref" if row["method"] == row["baseline"] else ("n/a" if not row["compared"] else f"{row['agree']}/{row['compared']}")
        spread = format_seconds_range(row["p25"], row["p75"])
        lines.append(
            f"| | | | {row['method']} | {format_seconds(row['median'])} | {spread} | {ratio} | {statuses} | {residual} | {agree} |"
        )
    if data.get("batch"):
        lines += [
            "",
            "| scenes | method | n_jobs | problems | solves/s | statuses | same as n_jobs=1 |",
            "| --- | --- | ---: | ---: | ---: | --- | --- |",
        ]
        for b in data["batch"]:
            if b["skipped"]:
                lines.append(f"| {b['scenes']} | {b['method']} | | {b['problems']} | skipped ({b['skipped']}) | | |")
                continue
            same = "-" if b["matches_serial"] is None else ("yes" if b["matches_serial"] else "no")
            lines.append(
                f"| {b['scenes']} | {b['method']} | {b['n_jobs']} | {b['problems']} | {b['per_second']:,.0f} "
                f"| {_counts(b['statuses'])} | {same} |"
            )
    if data.get("sweeps"):
        lines += ["", "| " + " | ".join(_SWEEP_COLUMNS) + " |", "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- | --- |"]
        lines += ["| " + " | ".join(_sweep_cells(row)) + " |" for row in data["sweeps"]]
        lines += ["", _SWEEP_CAPTION]
    if data.get("pipeline"):
        lines += [
            "",
            "| " + " | ".join(_PIPELINE_COLUMNS) + " |",
            "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- | --- |",
        ]
        lines += ["| " + " | ".join(_pipeline_cells(row)) + " |" for row in data["pipeline"]]
        lines += ["", _PIPELINE_CAPTION + ". " + _detect_growth(data.get("detect_growth"))]
    return "\n".join(lines) + "\n"


def write_results(result: BenchResult, folder: Path) -> tuple[Path, Path, Path]:
    """Write ``results.csv`` (one line per row), ``results.json`` (everything) and ``results.md`` into ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    csv_path, json_path, md_path = folder / "results.csv", folder / "results.json", folder / "results.md"
    with csv_path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=_CSV_FIELDS)
        writer.writeheader()
        for row in result.rows:
            record = row.to_dict()
            record["statuses"] = _counts(row.statuses)
            writer.writerow({k: "" if record[k] is None else record[k] for k in _CSV_FIELDS})
    data = result.to_dict()
    json_path.write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")
    md_path.write_text(markdown_tables(data), encoding="utf-8")
    return csv_path, json_path, md_path


def write_scaling_plot(result: BenchResult, path: Path) -> Path | None:
    """Log-log plot of median solve time against contacts for the scaling families; None without matplotlib."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
    series: dict[tuple[str, str], list[tuple[int, float]]] = {}
    for row in result.rows:
        answered = any(status != "failed" for status in row.statuses)
        if row.family in SCALING_FAMILIES and row.median is not None and answered:
            series.setdefault((row.family, row.method), []).append((row.contacts, row.median))
    series = {k: sorted(v) for k, v in series.items() if len(v) >= 2}
    if not series:
        return None
    colours = {"lp": "tab:red", "scip": "tab:purple", "fast": "tab:green", "paper": "tab:blue", "scipy-dense": "tab:orange"}
    styles = {"box-push-nf": ("o", "-"), "pile-nf": ("s", "-"), "box-push": ("^", "--"), "pile": ("v", "--")}
    fig, ax = plt.subplots(figsize=(7.5, 5.5))
    for (family, method), points in sorted(series.items()):
        marker, line = styles[family]
        ax.loglog(
            [c for c, _ in points],
            [t for _, t in points],
            marker=marker,
            linestyle=line,
            color=colours.get(method, "tab:gray"),
            label=f"{family} / {method}",
        )
    lo = min(c for pts in series.values() for c, _ in pts)
    hi = max(c for pts in series.values() for c, _ in pts)
    anchor = 1e-3
    for power, style in ((1.0, ":"), (1.5, "--")):
        ax.loglog([lo, hi], [anchor, anchor * (hi / lo) ** power], "k" + style, linewidth=0.8, label=f"n^{power:g} (slope guide)")
    ax.axhline(1.0, color="red", linewidth=0.8, label="1 s target")
    ax.set_xlabel("contacts in one problem")
    ax.set_ylabel("median time per solve [s]")
    ax.set_title("median solve time against contacts (failed rows left out)")
    ax.grid(True, which="both", linewidth=0.3)
    ax.legend(fontsize=7, ncol=2)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


# --------------------------------------------------------------------------- sweep throughput

_SWEEP_COLUMNS = (
    "sweep backend",
    "workers",
    "points",
    "wall",
    "certified solves/s",
    "ratio to serial",
    "one solve",
    "startup",
    "statuses",
    "same as serial",
)
_SWEEP_CAPTION = (
    "Sweep of the tip-or-slide box (push height x floor friction), every point certified and audited; warm workers. "
    "one solve = median solver time of a point (a point decided in a batch: its share of the batch's time): workers / one "
    "solve is what the solves alone allow, the rest is per-point overhead (scene read at each point, chunks shipped and "
    "collected); startup = the LocalCluster's start, not in wall"
)


def _sweep_cells(row: dict[str, Any]) -> list[str]:
    if row["skipped"]:
        return [row["backend"], str(row["workers"]), "", "", f"skipped ({row['skipped']})", "", "", "", "", ""]
    ratio = "-" if row["ratio_to_serial"] is None else f"{row['ratio_to_serial']:.2f}"
    same = "-" if row["matches_serial"] is None else ("yes" if row["matches_serial"] else "NO")
    startup = "-" if row["startup_seconds"] is None else format_seconds(row["startup_seconds"])
    return [
        row["backend"],
        str(row["workers"]),
        str(row["points"]),
        format_seconds(row["seconds"]),
        f"{row['per_second']:,.0f}",
        ratio,
        format_seconds(row["solve_seconds"]),
        startup,
        _counts(row["statuses"] or {}),
        same,
    ]


def _sweep_table(result: BenchResult) -> Table:
    table = Table(title="sweep throughput (certified 2-D solves, qs.sweep)", caption=_SWEEP_CAPTION)
    for name in _SWEEP_COLUMNS:
        table.add_column(name)
    for row in result.sweeps:
        table.add_row(*_sweep_cells(row.to_dict()))
    return table
