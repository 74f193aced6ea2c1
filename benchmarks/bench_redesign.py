"""design-plant and design-pid before and after issue 26's redesign (the
Topology registry, one PID pipeline over a ``Plant``), A/B in the same run: the
library calls on the seed's plant (fc 3500 Hz, zeta 0.2, LM741; the PID by ZN)
and the PID of a model plant (``K=2 tau=1m theta=200u``, AMIGO), each with and
without its SPICE run, timed in this tree and in a copy of the commit before the
redesign (:data:`BASE`, extracted with ``git archive`` into a temporary folder
and imported from there in its own process). The two trees' processes
alternate, round by round, so that the shared machine's load falls on both alike.

Each case runs in a fresh process, so its imports and first call (what a
command pays: a module imported at the top in one tree may be imported lazily in
the other; the caches empty, e.g. the reaction curve's tangent) are timed as
well as the repeat calls (a warm web worker's).

Times are CPU seconds (user + system, of the process and its simulator
children), not wall time: on a 2-core machine shared by several sessions the
wall time of the same call varies 2-4x from run to run, its CPU time far less.

Goal: the redesign no slower, the ratio new/old of the medians at most
:data:`GOAL_RATIO` (1 plus the run-to-run noise).
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: the commit before the redesign
BASE = "88d0b0b"
#: new/old median at most this (no slower, within the noise of a shared 2-core machine)
GOAL_RATIO = 1.10
ROUNDS, CALLS = 5, 3

#: case -> (library call, its keywords); the same in both trees
CASES = {
    "design-plant, seed plant": ("plant", dict(fc_hz=3500, zeta=0.2, opamp="LM741")),
    "design-pid, seed plant, ZN": ("pid", dict(plant_fc_hz=3500, plant_zeta=0.2, opamp="LM741")),
    "design-pid, model plant, AMIGO": ("pid", dict(plant_tf="K=2 tau=1m theta=200u", tuning="amigo",
                                                   opamp="LM741")),
}

WORKER = r"""
BLOCK_S = 0.5
import json, os, sys, time
def cpu():
    # this process at the clock's own resolution (os.times() counts 10 ms ticks: a 40 ms call was +-25 %), and
    # its reaped children (ngspice -b)
    t = os.times()
    return time.process_time() + t.children_user + t.children_system
kind, kw, sim, calls = json.loads(sys.argv[1])
tick = cpu()
if kind == "plant":
    from designer.plant.design import design_plant as run
    from designer.plant.spec import PlantSpec as Spec
else:
    from designer.pid.design import design_pid as run
    from designer.pid.spec import PidSpec as Spec
run(Spec(**kw), simulate=sim)                 # the imports and the first call: what a command pays
first = cpu() - tick
# the repeat calls as one block of at least `calls` calls and BLOCK_S seconds: its mean a call
tick, n = cpu(), 0
while n < calls or cpu() - tick < BLOCK_S:
    run(Spec(**kw), simulate=sim)
    n += 1
print(json.dumps({"first": first, "repeat": [(cpu() - tick) / n]}))
"""


def _tree_of(commit: str, into: Path) -> Path:
    """``designer/`` of ``commit`` extracted under ``into`` (git archive, no worktree left behind)."""
    archive = into / "base.tar"
    with open(archive, "wb") as fh:
        subprocess.run(["git", "-C", str(ROOT), "archive", commit, "designer"], stdout=fh, check=True)
    with tarfile.open(archive) as tar:
        tar.extractall(into, filter="data")
    return into


def _run(path: Path, cwd: Path, kind: str, kw: dict, sim: bool) -> dict:
    env = dict(os.environ, PYTHONPATH=str(path), MPLBACKEND="Agg")
    p = subprocess.run([sys.executable, "-c", WORKER, json.dumps([kind, kw, sim, CALLS])], capture_output=True,
                       text=True, env=env, cwd=cwd, timeout=900)
    if p.returncode != 0:
        raise RuntimeError(p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "worker failed")
    return json.loads(p.stdout.strip().splitlines()[-1])


def main(base: str = BASE):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "old").mkdir()
        old_tree = _tree_of(base, tmp / "old")
        new, old = {}, {}
        for _ in range(ROUNDS):
            for name, (kind, kw) in CASES.items():
                for sim in (False, True):
                    key = f"{name}{', SPICE' if sim else ', no SPICE'}"
                    for store, tree in ((old, old_tree), (new, ROOT)):
                        got = _run(tree, tmp, kind, kw, sim)
                        store.setdefault((key, "imports + first call"), []).append(got["first"])
                        store.setdefault((key, "repeat calls"), []).extend(got["repeat"])
    print(f"### design-plant and design-pid in-process, this tree against {base}"
          f"{' (before the redesign)' if base == BASE else ''}, "
          f"{ROUNDS} alternating rounds, a fresh process per case and round: its imports and first call, "
          f"then at least {CALLS} repeat calls and 0.5 s in one block (its mean a call); median CPU time (s), "
          f"the process's at its clock's resolution\n")
    print(f"Goal: new/old <= {GOAL_RATIO:g} (no slower, within a shared machine's noise).\n")
    print("| case | call | before (CPU s) | after (CPU s) | after/before | spread of before (max/min) | goal |")
    print("|---|---|---:|---:|---:|---:|---|")
    for (k, call), before in old.items():
        a, b = statistics.median(before), statistics.median(new[(k, call)])
        ratio = b / a
        print(f"| {k} | {call} | {a:.3f} | {b:.3f} | {ratio:.2f} | {max(before) / min(before):.2f} | "
              f"{'ok' if ratio <= GOAL_RATIO else 'MISSED'} |")


if __name__ == "__main__":
    main(*sys.argv[1:2])     # another commit to compare with, e.g. one change's parent
