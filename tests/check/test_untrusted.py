"""check-design's trust boundary, attacked as a stranger's pull request would
attack it (the README's "What a spec can and cannot do").

Every attack runs the real console script, under both simulator backends, in a
folder of its own with a fresh ``HOME``, and asserts: exit 2 and one line on
stderr naming the file at fault, no marker file written by any ``shell``
command, no file written outside ``--out``, and no process of ours left (read
from /proc by an environment mark every child inherits).
"""

import os
import subprocess
import time
import uuid
from pathlib import Path

import pytest

from helpers import processes_tagged, script, tagged_env, wait_gone

pytestmark = [pytest.mark.untrusted, pytest.mark.spice]

BACKENDS = ("pyspice", "ngspice-cli")
RC = ("rc test\nV1 in 0 PULSE(0 1 0 1u 1u 1m 2m)\nR1 in out 1k\nC1 out 0 100n\n{extra}\n.tran 1u 1m\n"
      ".meas tran vmax MAX v(out)\n.end\n")
SPEC = "name: attack\nkind: netlist\ndeck: {deck}\nchecks:\n  vmax: {{max: 2}}\n"


class Bench:
    """A repository folder (the spec's), a folder outside it, a HOME, and the markers folder."""

    def __init__(self, tmp_path: Path):
        self.tmp = tmp_path
        self.repo, self.outside, self.home, self.marks = (tmp_path / n for n in ("repo", "outside", "home", "marks"))
        for d in (self.repo, self.outside, self.home, self.marks):
            d.mkdir()
        self.tag = uuid.uuid4().hex

    def shell(self, name: str) -> str:
        """An ngspice script line that leaves marker ``name`` if it ever runs."""
        return f"shell touch {self.marks / name}"

    def control(self, name: str) -> str:
        return f".control\n{self.shell(name)}\n.endc"

    def write(self, rel: str, text: str, where: Path | None = None) -> Path:
        path = (where or self.repo) / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
        return path

    def snapshot(self) -> dict:
        """Every file under the test's folder but the output folder, with its bytes."""
        out = {}
        for p in sorted(self.tmp.rglob("*")):
            rel = p.relative_to(self.tmp).parts
            # matplotlib's own font cache in the fresh HOME is not ours
            if rel[:1] == ("out",) or rel[:3] == ("home", ".cache", "matplotlib") or not (p.is_file() or p.is_symlink()):
                continue
            out[p] = os.readlink(p) if p.is_symlink() else p.read_bytes()
        return out

    def run(self, command: str, *args, timeout: float = 120):
        env = tagged_env(self.tag, HOME=str(self.home))
        return subprocess.run([script(command), *map(str, args)], cwd=self.repo, env=env, capture_output=True,
                              text=True, timeout=timeout, stdin=subprocess.DEVNULL)

    def assert_clean(self, before: dict):
        assert not list(self.marks.iterdir()), "an ngspice command ran"
        assert self.snapshot() == before, "a file outside --out was written"
        assert wait_gone(self.tag) == [], "a process of ours outlived the command"


@pytest.fixture
def bench(tmp_path):
    return Bench(tmp_path)


def refused(bench, *args, words=(), command="check-design"):
    before = bench.snapshot()
    out = bench.run(command, *args)
    assert out.returncode == 2, out.stderr + out.stdout
    lines = out.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in out.stderr, out.stderr
    for w in words:
        assert w in lines[0], lines[0]
    bench.assert_clean(before)
    return lines[0]


# ---- decks are data ------------------------------------------------------------------

def _deck_attacks(b: Bench) -> dict:
    """name -> (deck text, {file: text} beside it, {file: text} outside the spec's folder, words)."""
    evil = b.control("m") + "\n"
    return {
        "include": (RC.format(extra=".include evil.inc"), {"evil.inc": evil}, {}, ("evil.inc:1",)),
        "inc-mixed-case": (RC.format(extra=".InC evil.inc"), {"evil.inc": "* models\n  .CoNtRoL\n"
                                                               + b.shell("m") + "\n.endc\n"}, {}, ("evil.inc:2",)),
        "include-quoted": (RC.format(extra='.include "my evil.inc"'), {"my evil.inc": evil}, {}, ("my evil.inc",)),
        "two-levels": (RC.format(extra=".include a.inc"), {"a.inc": "R9 out 0 1meg\n.include sub/b.inc\n",
                                                          "sub/b.inc": "* b\n" + evil}, {}, ("b.inc:2",)),
        "lib-section": (RC.format(extra=".lib models.lib tt"),
                        {"models.lib": ".lib tt\nR9 out 0 1meg\n.endl tt\n.lib ff\n" + evil + ".endl ff\n"}, {},
                        ("models.lib:5",)),
        "lib-nested": (RC.format(extra=".lib models.lib tt"),
                       {"models.lib": ".lib tt\n.lib inner.lib x\n.endl\n", "inner.lib": ".lib x\n" + evil + ".endl\n"},
                       {}, ("inner.lib:2",)),
        "continued-include": (RC.format(extra=".include\n+ evil.inc"), {"evil.inc": evil}, {}, ("evil.inc:1",)),
        "continued-control": (RC.format(extra=".con\n+trol\n" + b.shell("m") + "\n.endc"), {}, {}, ("deck.cir",)),
        "controlx": (RC.format(extra=".controlx\n" + b.shell("m") + "\n.endc"), {}, {}, ("deck.cir:5",)),
        "tab-upper-control": (RC.format(extra="\t.CONTROL\n" + b.shell("m") + "\n.endc"), {}, {}, ("deck.cir:5",)),
        "dots-control": (RC.format(extra="..control\n" + b.shell("m") + "\n.endc"), {}, {}, ("deck.cir:5",)),
        "star-hash": (RC.format(extra=".include evil.inc"), {"evil.inc": "*# " + b.shell("m") + "\n"}, {},
                      ("evil.inc:1", "'*#'")),
        "ng-script-title": ("*ng_script\n" + b.shell("m") + "\n", {}, {}, ("deck.cir:1", "*ng_script")),
        "ng-script-include": (RC.format(extra=".include evil.inc"), {"evil.inc": "*NG_SCRIPT\n" + b.shell("m")},
                              {}, ("evil.inc:1",)),
        "dotdot-include": (RC.format(extra=".include ../outside/evil.inc"), {}, {"evil.inc": evil},
                           ("outside", "deck.cir:5")),
        "absolute-include": (RC.format(extra=f".include {b.outside / 'evil.inc'}"), {}, {"evil.inc": evil},
                             ("outside",)),
        "home-include": (RC.format(extra=".include ~/evil.inc"), {}, {}, ("outside",)),
        "file-parameter": (RC.format(extra='.model src filesource (file="/etc/passwd" amploffset=[0])'), {}, {},
                           ("file=",)),
        "osdi": (RC.format(extra=".osdi /tmp/model.osdi"), {}, {}, (".osdi",)),
    }


ATTACKS = ["include", "inc-mixed-case", "include-quoted", "two-levels", "lib-section", "lib-nested",
           "continued-include", "continued-control", "controlx", "tab-upper-control", "dots-control", "star-hash",
           "ng-script-title", "ng-script-include", "dotdot-include", "absolute-include", "home-include",
           "file-parameter", "osdi"]


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", ATTACKS)
def test_a_deck_that_would_run_a_command_is_refused(bench, name, backend):
    deck, beside, outside, words = _deck_attacks(bench)[name]
    for rel, text in beside.items():
        bench.write(rel, text)
    for rel, text in outside.items():
        bench.write(rel, text, bench.outside)
    if name == "home-include":
        bench.write("evil.inc", bench.control("m") + "\n", bench.home)
    bench.write("deck.cir", deck)
    bench.write("spec.yaml", SPEC.format(deck="deck.cir"))
    refused(bench, "spec.yaml", "--simulator", backend, "--out", bench.tmp / "out", words=words)


@pytest.mark.parametrize("backend", BACKENDS)
def test_an_include_linked_out_of_the_folder_is_refused(bench, backend):
    bench.write("evil.inc", bench.control("m") + "\n", bench.outside)
    (bench.repo / "models").mkdir()
    (bench.repo / "models" / "opamp.inc").symlink_to(bench.outside / "evil.inc")
    bench.write("deck.cir", RC.format(extra=".include models/opamp.inc"))
    bench.write("spec.yaml", SPEC.format(deck="deck.cir"))
    refused(bench, "spec.yaml", "--simulator", backend, words=("models/opamp.inc", "outside"))


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_clean_deck_with_includes_runs_as_ngspice_would_run_it(bench, backend):
    # the same circuit through .include, .lib sections and a continuation: inlined, simulated, measured
    bench.write("parts/r.inc", "R1 in out\n+ 1k\n.end\n")
    bench.write("parts/models.lib", ".lib typ\nC1 out 0 100n\n.endl typ\n.lib big\nC1 out 0 1u\n.endl big\n")
    deck = ("rc test\nV1 in 0 PULSE(0 1 0 1u 1u 1m 2m)\n.include parts/r.inc\n.LIB 'parts/models.lib' typ\n"
            ".tran 1u 1m\n.meas tran vmax MAX v(out)\n.end\n")
    bench.write("deck.cir", deck)
    bench.write("spec.yaml", SPEC.format(deck="deck.cir"))
    before = bench.snapshot()
    out = bench.run("check-design", "spec.yaml", "--simulator", backend, "--out", bench.tmp / "out")
    assert out.returncode == 0, out.stderr
    bench.assert_clean(before)
    import json
    result = json.loads((bench.tmp / "out" / "attack" / "result.json").read_text())
    vmax = next(c["value"] for c in result["corners"][0]["cases"] if c["id"] == "vmax")
    # the figure the same circuit written out in one deck gives
    plain = bench.write("plain.cir", RC.format(extra=""), bench.outside)
    text = subprocess.run(["ngspice", "-b", "-n", str(plain)], capture_output=True, text=True, cwd=bench.outside,
                          timeout=60).stdout
    expected = float(text.split("vmax", 1)[1].split("=", 1)[1].split()[0])
    assert vmax == pytest.approx(expected, rel=1e-9)


# ---- paths stay home -----------------------------------------------------------------

PLANT = "name: p\nkind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nchecks:\n  overshoot_pct: {max: 80}\n"


@pytest.mark.parametrize("key, value", [
    ("deck", "../outside/deck.cir"), ("deck", "{outside}/deck.cir"), ("golden", "../outside/gold.csv"),
    ("golden", "{outside}/gold.csv"), ("golden", "~/gold.csv")])
@pytest.mark.parametrize("backend", BACKENDS)
def test_a_path_out_of_the_spec_folder_is_refused(bench, key, value, backend):
    bench.write("deck.cir", RC.format(extra=""), bench.outside)
    bench.write("deck.cir", RC.format(extra=""))
    value = value.format(outside=bench.outside)
    if key == "deck":
        body = SPEC.format(deck=value)
    else:
        body = SPEC.format(deck="deck.cir") + f"golden: {{file: '{value}', signals: [out]}}\n"
    bench.write("spec.yaml", body)
    refused(bench, "spec.yaml", "--update-golden", "--simulator", backend, words=("spec.yaml:", key))


@pytest.mark.parametrize("backend", BACKENDS)
def test_update_golden_never_writes_through_a_link(bench, backend):
    victim = bench.write("precious.txt", "keep me\n", bench.outside)
    (bench.repo / "golden").mkdir()
    (bench.repo / "golden" / "rc.csv").symlink_to(victim)
    bench.write("deck.cir", RC.format(extra=""))
    bench.write("spec.yaml", SPEC.format(deck="deck.cir") + "golden: {file: golden/rc.csv, signals: [out]}\n")
    refused(bench, "spec.yaml", "--update-golden", "--simulator", backend, words=("golden.file", "outside"))
    assert victim.read_text() == "keep me\n"


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_json_of_parts_out_of_the_folder_is_refused(bench, backend):
    bench.write("result.json", "{}", bench.outside)
    bench.write("spec.yaml", "kind: pid\nplant: {json: ../outside/result.json}\ntuning: zn\ndesign_checks: all\n")
    refused(bench, "spec.yaml", "--simulator", backend, words=("plant.json", "outside"))


def test_root_widens_the_folder_and_allow_outside_lifts_it(bench):
    bench.write("deck.cir", RC.format(extra=""), bench.outside)
    bench.write("spec.yaml", SPEC.format(deck="../outside/deck.cir"))
    refused(bench, "spec.yaml")
    assert bench.run("check-design", "spec.yaml", "--root", bench.tmp).returncode == 0
    assert bench.run("check-design", "spec.yaml", "--allow-outside").returncode == 0
    # trusted or not, a deck is data
    bench.write("deck.cir", RC.format(extra=bench.control("m")), bench.outside)
    refused(bench, "spec.yaml", "--allow-outside", words=(".control",))


@pytest.mark.parametrize("option", ["--junit", "--summary"])
@pytest.mark.parametrize("kind", ["symlink", "fifo", "device", "directory"])
@pytest.mark.parametrize("backend", BACKENDS)
def test_an_output_that_is_not_a_regular_file_is_refused_before_any_work(bench, option, kind, backend):
    bench.write("deck.cir", RC.format(extra=""))
    bench.write("spec.yaml", SPEC.format(deck="deck.cir"))
    target = bench.tmp / "out" / "report.xml"
    target.parent.mkdir()
    victim = bench.write("victim.txt", "keep me\n", bench.outside)
    if kind == "symlink":
        target.symlink_to(victim)
    elif kind == "fifo":
        os.mkfifo(target)
    elif kind == "directory":
        target.mkdir()
    else:
        target = Path(os.devnull)
    tick = time.monotonic()
    line = refused(bench, "spec.yaml", option, target, "--out", bench.tmp / "out" / "o", "--simulator", backend)
    assert option in line and time.monotonic() - tick < 20
    assert victim.read_text() == "keep me\n" and not (bench.tmp / "out" / "o").exists()
    assert Path(os.devnull).is_char_device()


@pytest.mark.parametrize("kind", ["symlink", "fifo"])
def test_identify_plot_is_never_written_through_a_link_or_a_fifo(bench, kind):
    import numpy as np
    t = np.linspace(0, 5e-3, 500)
    rows = "\n".join(f"{a:.6g},{1 - np.exp(-a / 1e-3):.6g}" for a in t)
    bench.write("step.csv", "t,y\n" + rows + "\n")
    victim = bench.write("victim.png", "keep me\n", bench.outside)
    target = bench.repo / "fit.png"
    if kind == "symlink":
        target.symlink_to(victim)
    else:
        os.mkfifo(target)
    refused(bench, "step.csv", "--plot", target, command="identify", words=("--plot",))
    assert victim.read_text() == "keep me\n"


# ---- bounded parsing -----------------------------------------------------------------

LAUGHS = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{n}: &{n} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n" for p, n in zip("abcdefgh", "bcdefghi"))


@pytest.mark.parametrize("body, words", [
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nchecks: {fn_hz: {max: 4k}}\nunknown:\n" + "".join(
        "  " + ln + "\n" for ln in LAUGHS.splitlines()), ("alias",)),
    ("kind: plant\nx: &x [*x]\n", ("alias",)),
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nchecks: {fn_hz: {max: 4k}}\nchecks: {zeta: {max: 1}}\n",
     ("duplicate", "checks")),
    ("kind: plant\ndescription: " + "x" * 100_000 + "\n", ("description",)),
])
@pytest.mark.parametrize("backend", BACKENDS)
def test_yaml_that_would_blow_up_is_refused_quickly(bench, body, words, backend):
    bench.write("spec.yaml", body)
    tick = time.monotonic()
    refused(bench, "spec.yaml", "--simulator", backend, words=("spec.yaml:",) + words)
    assert time.monotonic() - tick < 10


# ---- no init file ----------------------------------------------------------------------

def _plant_init_files(bench: Bench) -> list:
    """A .spiceinit leaving a marker in the current folder (the repository), the spec's folder,
    the deck's folder and HOME; their names."""
    places = {"cwd": bench.repo, "spec": bench.repo / "specs", "deck": bench.repo / "specs" / "decks",
              "home": bench.home}
    for name, folder in places.items():
        bench.write(".spiceinit", bench.shell(f"init-{name}") + "\n", folder)
    return list(places)


@pytest.mark.parametrize("backend", BACKENDS)
def test_no_spiceinit_runs_for_any_command(bench, backend):
    _plant_init_files(bench)
    bench.write("specs/decks/rc.cir", RC.format(extra=""))
    bench.write("specs/net.yaml", SPEC.format(deck="decks/rc.cir").replace("attack", "net"))
    bench.write("specs/plant.yaml", PLANT)
    out = bench.tmp / "out"
    runs = [("check-design", "specs/net.yaml", "specs/plant.yaml", "--jobs", "2", "--out", out / "c"),
            ("design-plant", "--fc", "3500", "--zeta", "0.2", "--out", out / "d"),
            ("analyze-plant", "--r1", "1k6", "--r2", "3k9", "--c1", "3n3", "--c2", "100n", "--out", out / "a"),
            ("design-pid", "--plant-fc", "3500", "--plant-zeta", "0.2", "--opamp", "TL072", "--out", out / "p"),
            ("analyze-pid", "--plant-r1", "805", "--plant-r2", "1k", "--plant-c1", "10n", "--plant-c2", "220n",
             "--r3", "12k", "--r4", "1.777k", "--r5", "22k", "--r6", "3.3k", "--r7", "14.356k", "--r8", "1.2k",
             "--r9", "10k", "--r10", "10k", "--r11", "10k", "--r12", "1.026k", "--r13", "26.048k", "--r14",
             "2.528k", "--r15", "10k", "--r16", "3.279k", "--r17", "1.716k", "--r18", "9.98k", "--c3", "4.7n",
             "--c4", "47n", "--out", out / "q")]
    before = bench.snapshot()
    for command, *args in runs:
        done = bench.run(command, *args, "--simulator", backend, timeout=300)
        assert done.returncode in (0, 1), (command, done.stderr)
        assert "Traceback" not in done.stderr
    bench.assert_clean(before)
    assert not processes_tagged(bench.tag)


# ---- a yield's keys are data too (issue 17) -------------------------------------------------

_YIELD_SPEC = "kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nchecks: {fn_hz: {min: 3k, max: 4k}}\n"


@pytest.mark.parametrize("extra, words", [
    ("yield: {min: 95%, engine: '$(ngspice)'}", ("spec.yaml:4:", "yield.engine")),
    ("yield: {min: 95%, samples: 99999999999}", ("spec.yaml:4:", "yield.samples")),
    ("yield: {min: '$(touch x)'}", ("spec.yaml:4:", "yield.min")),
    ("yield: {min: 95%}\ntolerances: {R: 1e999%}", ("spec.yaml:5:", "tolerances.R")),
    ("yield: {min: 95%}\ntolerances: {'../R': 1%}", ("spec.yaml:5:", "unknown key")),
])
def test_a_bad_yield_is_refused_before_any_work(bench, extra, words):
    bench.write("spec.yaml", _YIELD_SPEC + extra + "\n")
    refused(bench, "spec.yaml", "--out", bench.tmp / "out", words=words)
    assert not (bench.tmp / "out").exists()
