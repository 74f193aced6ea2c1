"""check.summary: the Markdown summary in the current language (issue 29): check-design's English by default
(its words and layout as they were), the Check page's Spanish with no English word of the summary's own; the
counts, the spec and corner names and the cases' lines are the same in both."""

import re

from designer.check.result import ERROR, FAIL, PASS, SIM_ERROR, SKIP, Case, CornerOutcome, SpecOutcome
from designer.check.summary import summary_markdown
from designer.core.i18n import catalogue, language

#: the summary's own words (its headings, its totals line, its table's header and result marks)
WORDS = ("all checks pass", "checks FAILED", "spec", "corner", "result", "passed", "failed", "errors",
         "report-only", "Failures and errors", "Warnings", "pass", "FAIL")


def outcome(name: str) -> SpecOutcome:
    """A spec with a case of every kind (a failure, an error, a report-only, a pass) and a warning."""
    cases = (Case("fn_hz", "TL072", FAIL, "fn_hz = 3 kHz below min 3.3 kHz"),
             Case("simulation", "TL072", ERROR, "simulation: ngspice stopped", error_kind=SIM_ERROR),
             Case("zeta", "TL072", SKIP, "report only: zeta 0.2"),
             Case("q", "TL072", PASS, "q fine"))
    corner = CornerOutcome("TL072", cases, warnings=("golden file was recorded elsewhere",), seconds=1.0)
    return SpecOutcome(name, f"/specs/{name}.yaml", "plant", [corner], {"name": "designer"})


def passing() -> SpecOutcome:
    corner = CornerOutcome("TL072", (Case("fn_hz", "TL072", PASS, "fn_hz = 3.5 kHz within 3.3 kHz to 3.7 kHz"),),
                           seconds=1.0)
    return SpecOutcome("lab3", "/specs/lab3.yaml", "plant", [corner], {"name": "designer"})


def words_of(md: str) -> set:
    """The summary's own words: its headings, the totals line and the table's header row (the rows below
    hold names and the cases' lines)."""
    lines = md.splitlines()
    own = [line for line in lines if line.startswith("#")] + [lines[2], lines[4]]
    return {w for line in own for w in re.findall(r"[A-Za-z][A-Za-z-]*", line)} - {"check-design"}


def test_the_english_summary_is_check_designs_whatever_language_is_current_outside_a_block():
    runs = ([outcome("x")], [passing()], [passing(), outcome("y")])
    for run in runs:
        md = summary_markdown(run, 1.5)
        with language("en"):
            assert summary_markdown(run, 1.5) == md
    md = summary_markdown([outcome("x")], 1.5)
    assert md.startswith("## check-design: checks FAILED\n\n1 specs, 4 checks: 1 passed, 1 failed, 1 errors, "
                         "1 report-only (1.5 s)\n")
    assert "| spec | corner | result | passed | failed | errors | report-only |" in md
    assert "### Failures and errors" in md and "### Warnings" in md and "| **ERROR** |" in md
    assert summary_markdown([passing()], 1.0).startswith("## check-design: all checks pass\n")


def test_the_spanish_summary_has_no_english_word_of_its_own():
    es = catalogue("es")
    english = {w for m in WORDS for w in re.findall(r"[A-Za-z][A-Za-z-]*", m)} - {"ERROR"}   # ERROR is Spanish too
    for run in ([outcome("x")], [passing()]):
        md_en = summary_markdown(run, 1.5)
        with language("es"):
            md = summary_markdown(run, 1.5)
        assert not words_of(md) & english, words_of(md) & english
        assert len(md.splitlines()) == len(md_en.splitlines())
        assert "1,5 s" in md   # the decimal comma, as every Spanish text
    with language("es"):
        failed = summary_markdown([outcome("x")], 1.0)
        ok = summary_markdown([passing()], 1.0)
    assert failed.startswith(f"## check-design: {es['checks FAILED']}\n") and f"### {es['Warnings']}" in failed
    assert f"### {es['Failures and errors']}" in failed and f"| **{es['ERROR']}** |" in failed
    assert ok.startswith(f"## check-design: {es['all checks pass']}\n") and f"| {es['pass']} |" in ok
    assert "| " + " | ".join(es[w] for w in ("spec", "corner", "result", "passed", "failed", "errors",
                                              "report-only")) + " |" in ok
