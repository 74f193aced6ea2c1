"""The Markdown summary of a ``check-design`` run, fit for
``$GITHUB_STEP_SUMMARY`` (or a merge request note): one line of totals, a
table with a row per spec and corner, then every failure and error, and the
warnings, each naming the spec, the corner and the value against its limit."""

from __future__ import annotations

from .junit import visible
from .result import ERROR, FAIL, PASS, SKIP, headline

__all__ = ["summary_markdown"]

_MARK = {PASS: "pass", FAIL: "**FAIL**", ERROR: "**ERROR**"}


def _cell(text: str) -> str:
    # control characters and lone surrogates (a file name that is not UTF-8) as visible escapes, as the JUnit
    # file has them; a line break (CR too, for Markdown) would end the table row
    return visible(text).replace("|", "\\|").replace("\r", " ").replace("\n", " ")


def summary_markdown(outcomes, seconds: float) -> str:
    """The summary (text) for a run's :class:`~designer.check.result.SpecOutcome` list.

    Parameters
    ----------
    outcomes : list of designer.check.result.SpecOutcome
        The run's specs and their corners.
    seconds : float
        The run's duration.

    Returns
    -------
    str
        The Markdown summary.
    """
    tot = {PASS: 0, FAIL: 0, SKIP: 0, ERROR: 0}
    for o in outcomes:
        for k, v in o.counts().items():
            if k in tot:
                tot[k] += v
    verdict = "all checks pass" if not (tot[FAIL] or tot[ERROR]) else "checks FAILED"
    lines = ["## check-design: " + verdict, "",
             f"{len(outcomes)} specs, {sum(tot.values())} checks: {tot[PASS]} passed, {tot[FAIL]} failed, "
             f"{tot[ERROR]} errors, {tot[SKIP]} report-only ({seconds:.1f} s)", "",
             "| spec | corner | result | passed | failed | errors | report-only |",
             "|---|---|---|---:|---:|---:|---:|"]
    problems, warnings = [], []
    for o in outcomes:
        for c in o.corners:
            n = {k: sum(1 for x in c.cases if x.status == k) for k in tot}
            status = ERROR if n[ERROR] else FAIL if n[FAIL] else PASS
            lines.append(f"| {_cell(o.name)} | {_cell(c.corner or '-')} | {_MARK[status]} | {n[PASS]} | {n[FAIL]} "
                         f"| {n[ERROR]} | {n[SKIP]} |")
            problems += [f"- {_cell(headline(o, x))}" for x in c.cases if x.status in (FAIL, ERROR)]
        warnings += [f"- {_cell(o.name)}: {_cell(w)}" for w in o.warnings]
    if problems:
        lines += ["", "### Failures and errors", "", *problems]
    if warnings:
        lines += ["", "### Warnings", "", *warnings]
    return "\n".join(lines) + "\n"
