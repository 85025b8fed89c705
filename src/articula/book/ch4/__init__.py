"""Chapter 4: DC motor current control (Sects. 4.2-4.3, Fig. 4.3, Figs. 4.5-4.9, bandwidth)."""

from __future__ import annotations

from articula.book.study import Section, Study


def reproduce(study: Study) -> Section:
    """Run the chapter's study into study.out; its markdown, numbers and claims."""
    from articula.book.ch4 import analysis, report
    from articula.book.ch4.study import run_study
    from articula.book.text import finite_or_none as num

    results = run_study(study)
    model = {
        "omega_c": results.model.omega_c,
        "omega_ss_per_volt": results.model.omega_per_volt,
        "i_ss_per_volt": results.model.current_per_volt,
    }
    claims = analysis.claims(model, results.runs, results.bandwidth)
    why = analysis.explanations(results.gains, results.runs, results.bandwidth)
    markdown = report.markdown(results, why, {c.name: c.verdict for c in claims})
    runs = {
        name: {key: value if key == "k" else num(value) for key, value in m.items()}
        for name, m in results.runs.items()
    }
    sweep = [
        {"k": r.k, "measured": num(r.measured), "predicted": num(r.predicted), "noise_rms": r.noise}
        for r in results.bandwidth
    ]
    return Section(markdown, {**model, "runs": runs, "bandwidth": sweep}, tuple(claims))
