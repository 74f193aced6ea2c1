"""benchmarks/run.py: a subset run replaces only its own sections of RESULTS.md."""

import importlib.util

from helpers import ROOT


def load_run():
    spec = importlib.util.spec_from_file_location("bench_run", ROOT / "benchmarks" / "run.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_sections_split_results_by_benchmark_in_file_order():
    run = load_run()
    text = ("# Benchmark results\n\nWritten then.\n\n## bench_a\n\nRun 1.\n\n### t\n\n| x |\n\n"
            "## bench_b\n\nRun 2.\n\nbody b\n")
    got = run.sections(text)
    assert list(got) == ["bench_a", "bench_b"]
    assert got["bench_a"].startswith("## bench_a\n") and "### t" in got["bench_a"] and "bench_b" not in got["bench_a"]
    assert got["bench_b"] == "## bench_b\n\nRun 2.\n\nbody b\n"


def test_the_committed_results_have_every_benchmark_with_its_run_time():
    run = load_run()
    got = run.sections((ROOT / "benchmarks" / "RESULTS.md").read_text())
    assert set(got) == {p.stem for p in (ROOT / "benchmarks").glob("bench_*.py")}
    assert all(body.split("\n")[2].startswith("Run ") for body in got.values())


def test_every_name_a_benchmark_imports_from_designer_exists():
    """A benchmark imports inside functions and in the code strings it runs in a new
    interpreter, so a renamed module breaks ``make bench`` long after the rename
    (bench_model_pid imported ``designer.pid.process_report`` after it was merged
    into ``designer.pid.report``): every such import resolves."""
    import importlib
    import re
    found = set()
    for path in sorted((ROOT / "benchmarks").glob("*.py")):
        for module, names in re.findall(r"from (designer[\w.]*) import ([\w ,]+)", path.read_text()):
            for name in names.split(","):
                found.add((path.name, module, name.split(" as ")[0].strip()))
    assert len(found) > 40
    missing = [f"{bench}: from {module} import {name}" for bench, module, name in sorted(found)
               if not hasattr(importlib.import_module(module), name)
               and importlib.util.find_spec(f"{module}.{name}") is None]
    assert not missing, missing
