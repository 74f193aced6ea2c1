"""What tests share: where things are, and the one way to find a console script
(the running interpreter's bin folder, so a clone anywhere, any venv, works)."""

import re
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


def tagged_env(tag: str, **extra) -> dict:
    """The environment for a command under test, marked with ``tag``: every process it
    starts (workers, the renderer, its helpers, ``ngspice -b``) inherits the mark."""
    import os
    return {**os.environ, "DESIGNER_TEST_TAG": tag, **extra}


def processes_tagged(tag: str) -> list:
    """Live processes whose environment carries ``tag`` (read from /proc: no ps needed;
    zombies, which hold nothing, are left out)."""
    found, mark = [], f"DESIGNER_TEST_TAG={tag}".encode()
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            if mark in (d / "environ").read_bytes().split(b"\0"):
                state = (d / "stat").read_text().rsplit(")", 1)[1].split()[0]
                if state != "Z":
                    found.append(int(d.name))
        except OSError:   # gone meanwhile, or not ours to read
            pass
    return found


def wait_gone(tag: str, seconds: float = 2.0) -> list:
    """The tagged processes still alive after ``seconds`` (polled; [] as soon as none is)."""
    import time
    deadline = time.monotonic() + seconds
    while True:
        left = processes_tagged(tag)
        if not left or time.monotonic() >= deadline:
            return left
        time.sleep(0.05)


def wilson_half_width(k: int, n: int, z: float = 1.959963984540054) -> float:
    """The 95 % Wilson score interval's half-width of k in n, written out here (not the package's)."""
    import math
    p = k / n
    lo = (p + z * z / (2 * n) - z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))) / (1 + z * z / n)
    hi = (p + z * z / (2 * n) + z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))) / (1 + z * z / n)
    return ((1.0 if k == n else hi) - (0.0 if k == 0 else lo)) / 2


#: an X line's op-amp pins, in the order the project's subcircuits take them
X_PINS = ("inp", "inn", "vcc", "vee", "out")


def deck_terminals(deck: str) -> dict:
    """(designator, terminal) -> net, read from the deck's element lines (R, C, X)."""
    out = {}
    inside = False       # the inlined op-amp models' own elements are not the circuit's
    for line in deck.splitlines():
        f = line.split()
        if f and f[0].lower() == ".subckt":
            inside = True
        elif f and f[0].lower() == ".ends":
            inside = False
        if inside or not f or f[0][0] not in "RCX":
            continue
        kind, name = f[0][0], f[0][1:]
        if kind in "RC":
            out[(f[0], "a")], out[(f[0], "b")] = f[1], f[2]
        else:
            out.update({(name, pin): net for pin, net in zip(X_PINS, f[1:6])})
    return out


def sheet_text_nodes(page: str) -> list:
    """The text a reader sees in a build sheet's HTML: every text node (stripped; the style sheet and
    the schematic's SVG left out) and every picture's alternative text."""
    from html.parser import HTMLParser

    class Nodes(HTMLParser):
        def __init__(self):
            super().__init__()
            self.out, self.skip = [], 0

        def handle_starttag(self, tag, attrs):
            if tag in ("style", "svg"):
                self.skip += 1
            alt = dict(attrs).get("alt") or dict(attrs).get("aria-label")
            if alt and not self.skip:
                self.out.append(alt.strip())

        def handle_endtag(self, tag):
            if tag in ("style", "svg"):
                self.skip -= 1

        def handle_data(self, data):
            if not self.skip and data.strip():
                self.out.append(data.strip())

    p = Nodes()
    p.feed(page)
    return p.out


def english_left(page: str, lang: str = "es") -> list:
    """The text nodes of a sheet in ``lang`` that are an English message of the catalogue whose
    translation differs (a word the sheet forgot to translate)."""
    from designer.core.i18n import catalogue
    english = {m for m, t in catalogue(lang).items() if t != m}
    return [n for n in sheet_text_nodes(page) if n in english or n.rstrip(":") in english]


WORD = re.compile(r"[A-Za-zÀ-ÿ]{3,}")
#: words the two languages share that the catalogue does not show as shared: units, symbols, proper names, file
#: names and formats (each a name, the same in Spanish)
SHARED_WORDS = {"ohm", "spice", "ngspice", "pyspice", "sallen", "key", "csv", "yaml", "zip", "json", "xml", "junit",
                "markdown", "fopdt", "sopdt", "arx", "iae", "prbs", "gbw", "wilson", "tektronix", "rigol", "siglent",
                "keysight", "picoscope", "digilent", "waveforms", "lab", "mso", "tds", "motor", "deg",
                # identify's methods and models, and the tuning rules, by the names they are chosen by
                "least", "squares", "overdamped", "underdamped", "optimize"}


def vocabulary(lang: str = "es") -> tuple:
    """(English-only words, ``lang``-only words) of the catalogue: the words of its English messages that no
    translation uses, and the other way round (:data:`SHARED_WORDS` out of both)."""
    from designer.core.i18n import catalogue
    cat = catalogue(lang)
    en = {w.lower() for m in cat for w in WORD.findall(m)}
    other = {w.lower() for t in cat.values() for w in WORD.findall(t)}
    return en - other - SHARED_WORDS, other - en - SHARED_WORDS


#: a snake_case or lower-case hyphenated identifier (a check's id, ``phase_margin``; identify's methods and models,
#: ``viteckova-double-pole``, typed as they are): a name, not words
IDENTIFIER = re.compile(r"\b\w+_\w+\b|\b[a-z0-9]+(?:-[a-z0-9]+)+\b")


def foreign(texts, words) -> list:
    """The texts holding a word of ``words`` (:func:`vocabulary`; identifiers left out), each with those words."""
    found = [(t, {w.lower() for w in WORD.findall(IDENTIFIER.sub(" ", t))} & words) for t in texts]
    return [(t, sorted(ws)) for t, ws in found if ws]


def sheet_command(exe: str, args, out, *more):
    """Run a sheet-writing command (``args`` its design's options, ``--out out``, then ``more``), which must
    succeed in silence; its standard output and its report folder (``--name``'s, the value after it in ``args``)."""
    import subprocess
    args = list(args)
    proc = subprocess.run([script(exe), *args, "--out", str(out), *more], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    return proc.stdout, Path(out) / "reports" / args[args.index("--name") + 1]


def spanish_sheet(exe: str, args, out):
    """A sheet-writing command run with ``--lang es`` (:func:`sheet_command`), its sheet checked for English
    messages left (:func:`english_left`); its summary, HTML page and text nodes."""
    summary, rep = sheet_command(exe, args, out, "--lang", "es")
    page = (rep / "build-sheet.html").read_text()
    assert english_left(page) == []
    return summary, rep, page, sheet_text_nodes(page)
