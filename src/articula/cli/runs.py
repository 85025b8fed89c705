"""`articula run` and `articula sweep`: any registered experiment, one config or a sweep."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from articula.cli.app import (
    CORES,
    Dask,
    Force,
    JsonFlag,
    OutDir,
    Workers,
    app,
    emit_json,
    metric_rows,
    out,
    print_table,
    progress_bar,
)
from articula.limits import MAX_RUNS


@app.command()
def run(
    config: Annotated[Path, typer.Argument(help="Experiment config (TOML).")],
    out_dir: OutDir,
    force: Force = False,
    as_json: JsonFlag = False,
) -> None:
    """Run one experiment config and write config.toml, record.json and trace.parquet.

    \b
    Example: articula run src/articula/book/ch2/configs/fuzzy_book_auto.toml --out runs/fuzzy
    """
    from articula.runs.registry import with_absolute_paths
    from articula.runs.runner import run_to_folder
    from articula.validation import load_toml

    data = with_absolute_paths(load_toml(config), config.parent)
    record = run_to_folder(data, out_dir, where=str(config), force=force)
    if as_json:
        emit_json(record)
    else:
        title = f"{record['experiment']} (seed {record['seed']})"
        print_table(title, ("metric", "value"), metric_rows(record["metrics"]))
        out.print(f"written to {out_dir}")
    if "not_tracked" in record:
        from articula.errors import InfeasibleError

        raise InfeasibleError(f"{record['not_tracked']}; the run folder {out_dir} is written")


@app.command()
def sweep(
    spec: Annotated[Path, typer.Argument(help="Sweep file (TOML with base, grid, runs).")],
    out_dir: OutDir,
    workers: Workers = CORES,
    dask: Dask = None,
    max_runs: Annotated[
        int, typer.Option(min=1, help="Refuse a sweep of more runs than this.")
    ] = MAX_RUNS,
    force: Force = False,
    as_json: JsonFlag = False,
) -> None:
    """Run every config of a sweep, skipping finished runs; writes results.parquet.

    \b
    Example: articula sweep src/articula/book/ch4/configs/bandwidth_quick.toml --out runs/bw
    """
    from articula.runs.backends import check_backend
    from articula.runs.folders import check_out
    from articula.runs.runner import RESULTS, run_sweep
    from articula.runs.sweep import expand_sweep
    from articula.validation import load_toml

    check_backend(dask)
    configs = expand_sweep(load_toml(spec), spec.parent, max_runs, str(spec))
    check_out(out_dir, "sweep", force)
    finished_before: list[int] = []  # the first progress call counts the runs found finished

    def report(done: int, total: int) -> None:
        if not finished_before:
            finished_before.append(done)
        bar.update(task, completed=done)

    with progress_bar(as_json) as bar:
        task = bar.add_task("sweep", total=len(configs))
        table = run_sweep(
            configs, out_dir, workers=workers, dask=dask, force=force, progress=report
        )
    failed = sum(error is not None for error in table.column("error").to_pylist())
    skipped = finished_before[0] if finished_before else 0
    summary = {
        "runs": table.num_rows,
        "skipped": skipped,
        "failed": failed,
        "results": str(out_dir / RESULTS),
    }
    if as_json:
        emit_json(summary)
    else:
        note = f" ({failed} could not be done: see the error column)" if failed else ""
        out.print(
            f"{summary['runs']} runs, {summary['runs'] - skipped} computed and {skipped} "
            f"already finished{note}; results in {summary['results']}"
        )
