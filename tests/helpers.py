"""What tests share: where things are, and the one way to find a console script
(the running interpreter's bin folder, so a clone anywhere, any venv, works)."""

import sys
import tracemalloc
from pathlib import Path

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent
FIXTURES = TESTS / "fixtures"
REPORTS = ROOT / "reports"
#: real scope exports from public lab repositories, beside the project (never copied into it)
EXT_CAPTURES = ROOT.parent / "shared" / "ext-captures"


def script(name: str) -> str:
    """Path of an installed console script of this environment."""
    path = Path(sys.executable).parent / name
    assert path.exists(), f"console script {name} not installed beside {sys.executable} (run make setup)"
    return str(path)


def peak_bytes(fn, *args, **kw):
    """Peak memory traced (numpy's allocations included) while ``fn`` runs, and its result."""
    tracemalloc.start()
    try:
        out = fn(*args, **kw)
        return tracemalloc.get_traced_memory()[1], out
    finally:
        tracemalloc.stop()
