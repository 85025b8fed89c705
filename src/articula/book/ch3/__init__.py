"""Chapter 3: six-chamber soft actuator and active damping (Figs. 3.2, 3.5 and 3.7) and beyond."""

from __future__ import annotations

from articula.book.study import Section, Study


def reproduce(study: Study) -> Section:
    """Run the chapter's study into study.out; its markdown, numbers and claims."""
    from articula.book.ch3 import analysis, report
    from articula.book.ch3.study import run_study

    results = run_study(study)
    sweep = results.delta
    data = {
        "delta": sweep.delta,
        "peak_deg": sweep.peak_deg,
        "settling_s": sweep.settling_s,
        "overshoot_pct": sweep.overshoot_pct,
        "open_ms": [1e3 * t for t in sweep.open_s],
        "search": {
            "book_timing": results.book_timing.data(),
            "timed": results.timed.data(),
            "side_30": results.directions.own.data(),
        },
    }
    markdown = report.markdown(results, analysis.findings(results))
    return Section(markdown, data, tuple(analysis.claims(sweep)))
