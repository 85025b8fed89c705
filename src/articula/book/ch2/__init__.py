"""Chapter 2: PID, piecewise and fuzzy PID of a PneuNet (Tables 2.2-2.3, Figs. 2.5-2.10)."""

from __future__ import annotations

from articula.book.study import Section, Study


def reproduce(study: Study) -> Section:
    """Run the chapter's study into study.out; its markdown, numbers and claims."""
    from articula.book.ch2 import analysis, report
    from articula.book.ch2.study import run_study

    results = run_study(study)
    findings = analysis.findings(results)
    table = results.comparison.table
    data = {
        "table_2_3": analysis.table_data(table),
        "table_2_2": analysis.tuning_data(results.tuning.manual, results.tuning.auto),
    }
    claims = analysis.claims(table, findings.kd_status)
    return Section(report.markdown(results, findings), data, tuple(claims))
