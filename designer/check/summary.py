"""The Markdown summary of a ``check-design`` run, fit for
``$GITHUB_STEP_SUMMARY`` (or a merge request note): one line of totals, a
table with a row per spec and corner, then every failure and error, and the
warnings, each naming the spec, the corner and the value against its limit.

Its words are in the current language (:mod:`designer.core.i18n`): ``check-design``
writes it in English (its default, byte for byte the same on every machine), the
Check page in the request's (issue 29: the Spanish page shows no English heading)."""

from __future__ import annotations

from ..core.i18n import N_
from ..core.i18n import gettext as _
from ..core.i18n import localise
from .junit import visible
from .result import ERROR, FAIL, PASS, SKIP, headline

__all__ = ["summary_markdown"]

#: a row's result (a failure or an error in bold)
_MARK = {PASS: N_("pass"), FAIL: N_("FAIL"), ERROR: N_("ERROR")}


def _mark(status: str) -> str:
    return _(_MARK[status]) if status == PASS else f"**{_(_MARK[status])}**"


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
    verdict = _("all checks pass") if not (tot[FAIL] or tot[ERROR]) else _("checks FAILED")
    head = [_("spec"), _("corner"), _("result"), _("passed"), _("failed"), _("errors"), _("report-only")]
    lines = ["## check-design: " + verdict, "",
             localise(_("{specs} specs, {checks} checks: {passed} passed, {failed} failed, {errors} errors, "
                        "{skipped} report-only ({seconds} s)").format(
                 specs=len(outcomes), checks=sum(tot.values()), passed=tot[PASS], failed=tot[FAIL],
                 errors=tot[ERROR], skipped=tot[SKIP], seconds=f"{seconds:.1f}")), "",
             "| " + " | ".join(head) + " |",
             "|---|---|---|---:|---:|---:|---:|"]
    problems, warnings = [], []
    for o in outcomes:
        for c in o.corners:
            n = {k: sum(1 for x in c.cases if x.status == k) for k in tot}
            status = ERROR if n[ERROR] else FAIL if n[FAIL] else PASS
            lines.append(f"| {_cell(o.name)} | {_cell(c.corner or '-')} | {_mark(status)} | {n[PASS]} | {n[FAIL]} "
                         f"| {n[ERROR]} | {n[SKIP]} |")
            problems += [f"- {_cell(headline(o, x))}" for x in c.cases if x.status in (FAIL, ERROR)]
        warnings += [f"- {_cell(o.name)}: {_cell(w)}" for w in o.warnings]
    if problems:
        lines += ["", "### " + _("Failures and errors"), "", *problems]
    if warnings:
        lines += ["", "### " + _("Warnings"), "", *warnings]
    return "\n".join(lines) + "\n"
