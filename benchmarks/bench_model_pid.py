"""design-pid for a plant known only as a model (issue 16): ``design-pid
--plant-tf "K=2 tau=1m theta=200u" --tuning optimize`` end to end (the console
script in a new process, files written to a temporary folder) against the floor
measured in the same run, the bare ``ngspice -b`` of the closed-loop deck it
wrote (``netlists/<name>.cir``); the two interleaved, medians of 5, so that the
machine's load hits both alike. Goal: within 2.5x.

Where the time goes: the same design split as the result's ``timings``
(tuning: the rule table and the optimiser; sizing: the E-series parts;
analytic: the loop as built, its checks and waveforms; SPICE; report: the
bundle, schematic and plots) and the imports, in a new interpreter each time
(what a new process pays, drawing in-process where the command forks its
renderer) and run after run in one process, medians of 3. (``result.json``
does not carry the timings: they are the in-memory result's.)
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PLANT = "K=2 tau=1m theta=200u"
#: issue 16: the end-to-end run within this many times the bare ngspice run of its own deck
RATIO_GOAL = 2.5
PHASES = ("tuning_s", "sizing_s", "analytic_s", "simulation_s", "report_s")


def end_to_end(repeat: int = 5):
    """Medians (s) of the console script and of ``ngspice -b`` of its deck, interleaved."""
    exe = str(Path(sys.executable).parent / "design-pid")
    cli, bare = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeat):
            t = time.perf_counter()
            p = subprocess.run([exe, "--plant-tf", PLANT, "--tuning", "optimize", "--name", "m", "--out", tmp],
                               capture_output=True, text=True)
            cli.append(time.perf_counter() - t)
            if p.returncode != 0:
                raise RuntimeError(p.stderr)
            deck = Path(tmp) / "netlists" / "m.cir"
            t = time.perf_counter()
            subprocess.run(["ngspice", "-b", str(deck)], check=True, capture_output=True, cwd=tmp)
            bare.append(time.perf_counter() - t)
    return statistics.median(cli), statistics.median(bare), cli, bare


#: the design in a new interpreter, drawing in-process (no renderer fork): the phases a new process pays
_COLD = """
import json, tempfile, time
tick = time.perf_counter()
from designer.pid.design import design_pid
from designer.pid.report import write_outputs
from designer.pid.spec import PidSpec
imports = time.perf_counter() - tick
res = design_pid(PidSpec(plant_tf=%r, tuning="optimize"))
with tempfile.TemporaryDirectory() as tmp:
    write_outputs(res, tmp, "m")
print(json.dumps({"imports_s": imports, **res.timings, "total_s": time.perf_counter() - tick}))
"""


def cold(repeat: int = 3) -> dict:
    """Median seconds per phase of the design in a new interpreter each time."""
    import json
    runs = [json.loads(subprocess.run([sys.executable, "-c", _COLD % PLANT], check=True, capture_output=True,
                                      text=True).stdout) for _ in range(repeat)]
    return {k: statistics.median(r.get(k, 0.0) for r in runs) for k in ("imports_s",) + PHASES + ("total_s",)}


def warm(repeat: int = 3):
    """Median seconds per phase of the same design in this process, run after run (imports paid before)."""
    from designer.pid.design import design_pid
    from designer.pid.report import write_outputs
    from designer.pid.spec import PidSpec
    runs, res = [], None
    for _ in range(repeat):
        tick = time.perf_counter()
        res = design_pid(PidSpec(plant_tf=PLANT, tuning="optimize"))
        with tempfile.TemporaryDirectory() as tmp:
            write_outputs(res, tmp, "m")
        runs.append({"imports_s": 0.0, **res.timings, "total_s": time.perf_counter() - tick})
    keys = ("imports_s",) + PHASES + ("total_s",)
    return {k: statistics.median(r.get(k, 0.0) for r in runs) for k in keys}, res


def main():
    cli, bare, clis, bares = end_to_end()
    ratio = cli / bare
    print(f"### `design-pid --plant-tf \"{PLANT}\" --tuning optimize` against its own deck in bare ngspice "
          f"(interleaved, median of {len(clis)}; goal <= {RATIO_GOAL:g}x)\n")
    print("| measure | seconds |")
    print("|---|---|")
    print(f"| `ngspice -b netlists/m.cir` (the floor) | {bare:.3f} |")
    print(f"| `design-pid --plant-tf ... --tuning optimize` (new process, schematic, plots, sheets) | {cli:.3f} |")
    print(f"| ratio (goal <= {RATIO_GOAL:g}) | {ratio:.1f}x {'ok' if ratio <= RATIO_GOAL else 'MISSED'} |")
    print(f"\nEach run (s): design-pid {', '.join(f'{x:.2f}' for x in clis)}; "
          f"ngspice -b {', '.join(f'{x:.2f}' for x in bares)}.\n")
    first, (again, res) = cold(), warm()
    keys = ("imports_s",) + PHASES + ("total_s",)
    print("### Where the time goes (median of 3, s): the design in a new interpreter (drawing in-process), and "
          "again in one process (imports and first calls paid)\n")
    print("| run | " + " | ".join(k[:-2] for k in keys) + " |")
    print("|---|" + "---|" * len(keys))
    for label, row in (("new interpreter", first), ("warm, same process", again)):
        print(f"| {label} | " + " | ".join(f"{row[k]:.2f}" for k in keys) + " |")
    opt = res.optimizer
    extra = f", {opt.evaluations} optimiser evaluations" if opt is not None else ""
    print(f"\n- design: Kp {res.kp:.4g}, Ti {res.ti_s * 1e6:.4g} us, Td {res.td_s * 1e6:.4g} us{extra}; "
          f"failed checks: {', '.join(c.id for c in res.checks if not c.ok) or 'none'}")
    print(f"- the SPICE phase of a new process, {first['simulation_s']:.2f} s, is {first['simulation_s'] / bare:.1f}x "
          f"the bare deck's {bare:.2f} s; the floor alone leaves {RATIO_GOAL * bare - bare:.2f} s for everything "
          f"else within the goal, where tuning, analysis, report and imports take "
          f"{first['total_s'] - first['simulation_s']:.2f} s")


if __name__ == "__main__":
    main()
