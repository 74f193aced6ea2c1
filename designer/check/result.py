"""What ``check-design`` found, typed until the JSON edge: a :class:`Case` per
check and corner, a :class:`CornerOutcome` per corner (its cases, the design's
own JSON, versions, warnings, files) and a :class:`SpecOutcome` per spec. The
JUnit file, the Markdown summary, the terminal lines and each spec's
``result.json`` all render these; none recomputes a verdict.

Exit status (:func:`exit_status`): 2 when a spec proved bad while running (a
deck ngspice cannot read, a design the spec's numbers cannot give), else 3 when
the simulator failed or timed out, else 1 when a check failed, else 0.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..core.errors import EXIT_BAD_INPUT, EXIT_CHECK_FAILED, EXIT_OK, EXIT_SIMULATOR
from ..core.jsonio import SCHEMA_VERSION, json_safe

__all__ = ["Case", "CornerOutcome", "ERROR", "FAIL", "PASS", "SIM_ERROR", "SKIP", "SPEC_ERROR", "SpecOutcome",
           "exit_status", "headline"]

PASS, FAIL, SKIP, ERROR = "pass", "fail", "skipped", "error"
#: what went wrong in an ERROR case: the spec (exit 2) or the simulator (exit 3)
SPEC_ERROR, SIM_ERROR = "spec", "simulator"


@dataclass(frozen=True)
class Case:
    """One check on one corner: its stable id (a figure, a design check id,
    ``spice_agreement``, ``tolerance_<figure>``, ``golden_<signal>``, or
    ``simulation`` for a run that gave nothing), its status, the value against
    its limit in words, the value and the limit (None where there is none)."""

    id: str
    corner: str
    status: str
    message: str
    value: float | None = None
    limit: str | None = None
    error_kind: str | None = None   #: SPEC_ERROR or SIM_ERROR for an ERROR case
    would_pass: bool | None = None  #: a report-only case: whether it is inside its limits

    def to_dict(self) -> dict:
        return {"id": self.id, "corner": self.corner, "status": self.status, "message": self.message,
                "value": self.value, "limit": self.limit, "error_kind": self.error_kind,
                "would_pass": self.would_pass}


@dataclass
class CornerOutcome:
    """One corner of one spec: its cases, the design's own JSON (``result.json``
    of the design command; a deck's measurements), what produced it (``tool``),
    warnings (e.g. a golden file recorded by another version), files written
    and the seconds it took."""

    corner: str
    cases: tuple
    design: dict | None = None
    tool: dict = field(default_factory=dict)
    warnings: tuple = ()
    files: dict = field(default_factory=dict)
    seconds: float = 0.0

    def to_dict(self) -> dict:
        return {"corner": self.corner, "seconds": self.seconds, "tool": self.tool,
                "warnings": list(self.warnings), "cases": [c.to_dict() for c in self.cases],
                "files": self.files, "design": self.design}


@dataclass
class SpecOutcome:
    """One spec file's run: every corner's outcome, in the spec's corner order."""

    name: str
    file: str
    kind: str
    corners: list
    tool: dict = field(default_factory=dict)
    files: dict = field(default_factory=dict)

    @property
    def cases(self) -> list:
        return [c for o in self.corners for c in o.cases]

    def counts(self) -> dict:
        """Cases by status: pass, fail, skipped, error, and tests (all of them)."""
        out = {PASS: 0, FAIL: 0, SKIP: 0, ERROR: 0}
        for c in self.cases:
            out[c.status] += 1
        out["tests"] = sum(out.values())
        return out

    @property
    def status(self) -> str:
        """The spec's verdict: error, fail or pass (report-only cases never fail it)."""
        n = self.counts()
        return ERROR if n[ERROR] else FAIL if n[FAIL] else PASS

    @property
    def warnings(self) -> list:
        return [w for o in self.corners for w in o.warnings]

    def to_dict(self) -> dict:
        """The spec's ``result.json`` under ``--out``."""
        return json_safe({"schema_version": SCHEMA_VERSION, "tool": self.tool,
                          "spec": {"name": self.name, "file": self.file, "kind": self.kind},
                          "status": self.status, "counts": self.counts(), "files": self.files,
                          "corners": [o.to_dict() for o in self.corners]})


def exit_status(outcomes) -> int:
    """2 a spec proved bad, 3 a simulator error or timeout, 1 a check failed, 0 all passed.

    Parameters
    ----------
    outcomes : list of SpecOutcome
        The run's specs and their corners.

    Returns
    -------
    int
        The command's exit status.
    """
    cases = [c for o in outcomes for c in o.cases]
    if any(c.status == ERROR and c.error_kind == SPEC_ERROR for c in cases):
        return EXIT_BAD_INPUT
    if any(c.status == ERROR for c in cases):
        return EXIT_SIMULATOR
    if any(c.status == FAIL for c in cases):
        return EXIT_CHECK_FAILED
    return EXIT_OK


def headline(outcome: SpecOutcome, case: Case) -> str:
    """One line naming the spec, the corner and the value against its limit:
    ``lab3-plant [TL072]: overshoot_pct = 55.2 above max 55`` (every case's
    message starts with what it checks).

    Parameters
    ----------
    outcome : SpecOutcome
        The spec's outcome.
    case : Case
        The check (a corner's figure against its limit).

    Returns
    -------
    str
        The line.
    """
    corner = f" [{case.corner}]" if case.corner else ""
    return f"{outcome.name}{corner}: {case.message}"
