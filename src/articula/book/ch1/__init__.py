"""Chapter 1: BAORNN obstacle avoidance of a redundant arm (Figs. 1.4-1.12) and its baselines."""

from __future__ import annotations

from articula.book.study import Section, Study


def reproduce(study: Study) -> Section:
    """Run the chapter's study into study.out; its markdown, numbers and claims."""
    from articula.book.ch1 import analysis, report
    from articula.book.ch1.book_values import BOOK_RUNS
    from articula.book.ch1.study import run_study

    results = run_study(study)
    table = analysis.comparison(results.metrics)
    data = {"runs": {r.name: results.metrics[r.name] for r in BOOK_RUNS}, "comparison": table}
    markdown = report.markdown(results, table, study.full)
    return Section(markdown, data, tuple(analysis.claims(results.metrics, table)))
