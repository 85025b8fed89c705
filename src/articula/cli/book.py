"""`articula reproduce` and `articula motor analyze`: the book's studies and its motor numbers."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from articula.book.claims import VERDICTS
from articula.cli.app import (
    CORES,
    Dask,
    Force,
    JsonFlag,
    OutDir,
    Workers,
    app,
    emit_json,
    motor_app,
    out,
    print_table,
    progress_bar,
)


@app.command()
def reproduce(
    chapter: Annotated[str, typer.Argument(help="ch1, ch2, ch3, ch4 or all.")] = "all",
    out_dir: OutDir = Path("report"),
    full: Annotated[bool, typer.Option("--full", help="Full-size runs instead of quick.")] = False,
    workers: Workers = CORES,
    dask: Dask = None,
    force: Force = False,
    as_json: JsonFlag = False,
) -> None:
    """Reproduce the book's figures and tables into OUT/report.md and PNG figures.

    \b
    Example: articula reproduce ch4 --out report --full
    """
    from articula.book.reproduce import check_chapter
    from articula.book.reproduce import reproduce as run_reproduce
    from articula.runs.backends import check_backend
    from articula.runs.folders import check_out

    check_chapter(chapter)
    check_backend(dask)
    check_out(out_dir, "report", force)
    with progress_bar(as_json) as bar:
        task = bar.add_task("reproduce", total=None)

        def step(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        def stage(name: str) -> None:
            bar.reset(task, total=None, description=f"reproduce {name}: runs")

        summary = run_reproduce(chapter, out_dir, full, workers, dask, step, force, stage)
    if as_json:
        emit_json(summary)
        return
    chapters = summary["chapters"].items()
    rows = [(name, *verdict_counts(data["claims_detail"])) for name, data in chapters]
    print_table("the book's claims", ("chapter", *VERDICTS), rows)
    out.print(f"report written to {summary['report']}")


def verdict_counts(details: list[dict[str, Any]]) -> tuple[str, ...]:
    """How many of a chapter's claims have each verdict, in VERDICTS' order.

    Args:
        details: the chapter's claims_detail (each with its verdict).

    Returns:
        The counts as table cells (reproduced, not reproduced, inconclusive).
    """
    return tuple(str(sum(d["verdict"] == v for d in details)) for v in VERDICTS)


@motor_app.command("analyze")
def motor_analyze(
    preset: Annotated[str | None, typer.Option(help="table4.1 or table4.2.")] = None,
    params: Annotated[
        Path | None,
        typer.Option(
            help="TOML with R, K, b, J, L (SI), or a [motor] table of them (identify's plant.toml)."
        ),
    ] = None,
    voltage: Annotated[float, typer.Option(help="Supply voltage V [V].")] = 12.0,
    torque: Annotated[float, typer.Option(help="External torque τ_ex [N·m].")] = 0.0,
    current: Annotated[float, typer.Option(help="Current for ω_c [A].")] = 1.0,
    as_json: JsonFlag = False,
) -> None:
    """State space (4.6), G(s) (4.7), steady state (4.8) and critical speed ω_c of a motor.

    \b
    Example: articula motor analyze --preset table4.2 --voltage 9 --torque -0.1 --json
    """
    from articula.book.ch4.motor_analysis import analyze, load_params

    result = analyze(load_params(preset, params), voltage, torque, current)
    if as_json:
        emit_json(result)
        return
    ss = result["steady_state"]
    out.print(
        f"A = {_numbers(result['A'])}\nB = {_numbers(result['B'])}\n"
        f"poles = {_numbers(result['poles'])}"
    )
    for k, tf in result["transfer"].items():
        out.print(f"{k:>13}: num {_numbers(tf['num'])}  den {_numbers(tf['den'])}")
    out.print(
        f"steady state at V={voltage} V, τ_ex={torque} N·m: "
        f"ω = {ss['omega']:.6g} rad/s, i = {ss['i']:.6g} A"
    )
    if result["omega_c"] is None:
        out.print(f"ω_c: none ({result['omega_c_note']})")
    else:
        out.print(f"ω_c at V={voltage} V, i={current} A: {result['omega_c']:.6g} rad/s")


def _numbers(values: Any) -> str:
    """A nested list of numbers to six significant digits (no float noise like 4.4849999); a
    complex pole, {"re", "im"} in the JSON, as a±bj."""
    if isinstance(values, list | tuple):
        return "[" + ", ".join(_numbers(v) for v in values) + "]"
    if isinstance(values, dict):
        return f"{values['re']:.6g}{values['im']:+.6g}j"
    return f"{values:.6g}"
