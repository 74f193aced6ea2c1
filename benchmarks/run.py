"""Run every ``benchmarks/bench_*.py`` (each has a ``main()`` that prints
Markdown) and write the collected output to ``benchmarks/RESULTS.md``.

Goals are checked and reported here, never in unit tests: the machines are
shared and noisy. ``python benchmarks/run.py [name ...]`` runs a subset and
replaces only those sections of RESULTS.md (each section says when it ran),
keeping the others.
"""

from __future__ import annotations

import contextlib
import importlib.util
import re
import io
import os
import platform
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
RESULTS = HERE / "RESULTS.md"


def sections(text: str) -> dict:
    """``## bench_name`` -> that section's text (heading included), in file order."""
    found = re.split(r"(?m)^(?=## bench_)", text)
    return {m.group(1): part.rstrip() + "\n" for part in found
            if (m := re.match(r"## (bench_\w+)", part))}


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    benches = sorted(HERE.glob("bench_*.py"))
    if argv:
        benches = [b for b in benches if any(a in b.stem for a in argv)]
    when = time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())
    machine = f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}"
    done = sections(RESULTS.read_text()) if argv and RESULTS.exists() else {}
    failed = 0
    for path in benches:
        spec = importlib.util.spec_from_file_location(path.stem, path)
        mod = importlib.util.module_from_spec(spec)
        buf = io.StringIO()
        print(f"== {path.name}", file=sys.stderr)
        try:
            with contextlib.redirect_stdout(buf):
                spec.loader.exec_module(mod)
                mod.main()
        except Exception as exc:  # one broken benchmark must not hide the others
            failed += 1
            buf.write(f"\n**{path.name} failed: {type(exc).__name__}: {exc}**\n")
        text = buf.getvalue().strip()
        print(text, file=sys.stderr)
        done[path.stem] = f"## {path.stem}\n\nRun {when} on {machine}.\n\n{text}\n"
    head = ["# Benchmark results\n", f"Written {when} by `make bench` (`benchmarks/run.py`); each section says "
            "when it ran.\n"]
    from designer.core.fileio import atomic_write
    atomic_write(RESULTS, "\n".join(head + [done[k] for k in sorted(done)]))
    print(f"wrote {RESULTS}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
