"""The simulator behind one small interface, with two backends.

- ``pyspice`` (default): ngspice as a shared library through PySpice.
- ``ngspice-cli``: ``ngspice -b -r out.raw deck.cir`` in a subprocess; the
  binary raw file is read with numpy.

Both take the same standalone deck text and return a :class:`SimResult`.
Neither lets ngspice read a file we did not write: each run happens in a
private, empty working folder (removed after it), ``ngspice -b -n`` skips the
user's ``.spiceinit`` (and ``HOME`` points at that folder), and the shared
library is started in such a folder too (ngspice 39's library reads
``.spiceinit`` from its working folder when it starts and has no switch to
skip it). ``ngspice -b`` dies with the process that started it
(:mod:`designer.core.lifetime`).
ngspice writes notes ("Note: ...", "Warning: ...") on stderr during normal
runs; PySpice 1.5 treats any stderr line as an error (and breaks outright on
ngspice >= 42), so neither backend trusts stderr alone: a run fails only when
ngspice reports an error line or produces no data.
"""

from __future__ import annotations

import contextvars
import os
import re
import shutil
import subprocess
import tempfile
import sys
import threading
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core import lifetime
from ..core.errors import DeckError, DesignError, SimulatorError

__all__ = ["DEFAULT_TIMEOUT_S", "NgspiceCli", "PySpiceShared", "error_lines", "get_simulator", "measure_names",
           "ngspice_version", "private_env", "read_raw", "recorded_command", "tool_info", "with_raw_output"]

INSTALL_HINT = "install it with: apt-get install ngspice libngspice0-dev (or run `make setup`)"
BACKENDS = ("pyspice", "ngspice-cli")

_MEAS = re.compile(r"^\s*([A-Za-z_][\w]*)\s*=\s*([-+]?[\d.]+(?:[eE][-+]?\d+)?)", re.M)
# a failed .meas ("name failed!", "meas ... failed") is a missing measurement, not a failed run
_ERROR = re.compile(r"^(?:.*\berror\b.*|.*fatal.*|.*aborted.*|.*timestep too small.*)$", re.I | re.M)
_NOT_ERROR = re.compile(r"^\s*(?:note|warning|info)\b", re.I)


@dataclass
class SimResult:
    """Vectors by lower-case name (``time``, node names such as ``out``; ``v(out)``
    also works), ``.meas`` results, and the log."""

    vectors: dict
    measurements: dict = field(default_factory=dict)
    log: str = ""
    backend: str = ""

    def __getitem__(self, name):
        key = name.lower()
        if key in self.vectors:
            return self.vectors[key]
        inner = re.sub(r"^v\((.*)\)$", r"\1", key)
        if inner in self.vectors:
            return self.vectors[inner]
        raise KeyError(f"no vector {name!r} in the simulation (have {', '.join(sorted(self.vectors))})")


_MEAS_DEF = re.compile(r"^\s*\.meas\w*\s+\w+\s+(\w+)", re.I | re.M)
#: what ngspice says when it cannot read a deck (as opposed to failing to simulate it)
_LOAD_ERROR = re.compile(r"error on line|unknown subckt|bad syntax|no circuit loaded|unknown device|"
                         r"unable to find definition of model|could not find a valid modelname|"
                         r"unknown model", re.I)


def measure_names(deck: str) -> list:
    """The names of a deck's ``.meas`` statements, lower case (as ngspice prints them).

    Parameters
    ----------
    deck : str
        The deck's text.

    Returns
    -------
    list of str
        The names, in the deck's order, each once.
    """
    return list(dict.fromkeys(m.lower() for m in _MEAS_DEF.findall(deck)))


def deck_refused(log: str) -> bool:
    """Whether ngspice's output says it could not read the deck (a :class:`DeckError`)."""
    return bool(_LOAD_ERROR.search(log))


def parse_measurements(text: str, deck: str) -> dict:
    """The ``name = value`` lines that ngspice prints for the deck's ``.meas``
    statements (a measurement that failed is absent)."""
    wanted = set(measure_names(deck))
    out = {}
    for m in _MEAS.finditer(text):
        if m.group(1).lower() in wanted:
            out[m.group(1).lower()] = float(m.group(2))
    return out


def error_lines(text: str) -> list:
    """ngspice's real error lines, notes and warnings left out.

    Parameters
    ----------
    text : str
        ngspice's output.

    Returns
    -------
    list of str
        Its error lines, stripped.
    """
    lines = [ln.strip() for ln in _ERROR.findall(text)]
    return [ln for ln in lines if ln and not _NOT_ERROR.match(ln)]


def read_raw(path) -> dict:
    """Read an ngspice raw file (binary or ASCII, real or complex data) into a
    dict of arrays; a missing, truncated or corrupt file is a :class:`SimulatorError`.

    Parameters
    ----------
    path : path-like
        The raw file.

    Returns
    -------
    dict
        Vector name -> numpy array.
    """
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise SimulatorError(f"cannot read the ngspice raw file {str(path)!r}: {exc.strerror or exc}") from None
    try:
        return parse_raw(data)
    except (ValueError, IndexError, AttributeError, UnicodeDecodeError) as exc:
        raise SimulatorError(f"the ngspice raw file {str(path)!r} is unreadable ({exc})") from None


def parse_raw(data: bytes) -> dict:
    """The vectors of an ngspice raw file's bytes; ValueError if malformed."""
    if not data:
        raise ValueError("it is empty")
    marker_b, marker_a = b"Binary:\n", b"Values:\n"
    header_end = data.find(marker_b)
    binary = header_end >= 0
    if not binary:
        header_end = data.find(marker_a)
    if header_end < 0:
        raise ValueError("no data section")
    header = data[:header_end].decode("latin-1")
    nv = re.search(r"No\. Variables:\s*(\d+)", header)
    npt = re.search(r"No\. Points:\s*(\d+)", header)
    fl = re.search(r"Flags:\s*(.*)", header)
    if not (nv and npt and fl and "Variables:\n" in header):
        raise ValueError("its header lacks the variable count, point count or flags")
    nvars, npts = int(nv.group(1)), int(npt.group(1))
    cplx = "complex" in fl.group(1)
    names = [ln.split()[1].lower() for ln in header.split("Variables:\n", 1)[1].strip().splitlines()[:nvars]]
    if nvars < 1 or len(names) != nvars:
        raise ValueError(f"it declares {nvars} variables and lists {len(names)}")
    body = data[header_end + (len(marker_b) if binary else len(marker_a)):]
    width = 2 if cplx else 1
    if binary:
        need = npts * nvars * width * 8
        if len(body) < need:
            raise ValueError(f"it is truncated ({len(body)} of {need} data bytes)")
        arr = np.frombuffer(body[:need], dtype="<f8").reshape(npts, nvars * width)
    else:
        rows = [ln.split() for ln in body.decode("latin-1").splitlines() if ln.strip()]
        # ASCII: a point index then the first value on one line, one value per line after
        vals = [r[-1] for r in rows]
        nums = []
        for v in vals[: npts * nvars]:
            parts = v.split(",")
            nums.extend(float(x) for x in parts[:width])
        if len(nums) < npts * nvars * width:
            raise ValueError("it is truncated")
        arr = np.array(nums).reshape(npts, nvars * width)
    if cplx:
        return {name: arr[:, 2 * i] + 1j * arr[:, 2 * i + 1] for i, name in enumerate(names)}
    return {name: np.array(arr[:, i]) for i, name in enumerate(names)}


def _result(vectors: dict, log: str, backend: str, deck: str) -> SimResult:
    # the raw file says v(out), the shared library out: one naming for both backends
    vectors = {re.sub(r"^v\((.*)\)$", r"\1", k.lower()): v for k, v in vectors.items()}
    if "frequency" in vectors:
        vectors["frequency"] = np.real(vectors["frequency"])
    if "time" in vectors:
        # ngspice can emit a repeated time point at breakpoints; keep time strictly increasing
        t = vectors["time"]
        keep = np.concatenate([[True], np.diff(t) > 0])
        vectors = {k: v[keep] for k, v in vectors.items()}
    return SimResult(vectors=vectors, measurements=parse_measurements(log, deck), log=log, backend=backend)


def with_raw_output(deck: str, raw_path) -> str:
    """The deck with a ``.control`` block that runs it and writes a binary raw file.

    ``ngspice -b -r file`` would be simpler but disables ``.meas`` in batch mode.

    Parameters
    ----------
    deck : str
        The deck's text (its ``.end`` line is replaced).
    raw_path : path-like
        Where ngspice writes the raw file.

    Returns
    -------
    str
        The deck with its ``.control`` block and ``.end``.
    """
    lines = deck.rstrip().splitlines()
    if lines and lines[-1].strip().lower() == ".end":
        lines = lines[:-1]
    control = [".control", "set filetype=binary", "run", f"write {raw_path}", "quit", ".endc", ".end"]
    return "\n".join(lines + control) + "\n"


class NgspiceCli:
    """``ngspice -b`` in a subprocess; exit status, error lines and a missing raw
    file decide failure, not stderr."""

    name = "ngspice-cli"

    def __init__(self, executable: str = "ngspice", timeout: float = 120.0):
        self.executable = executable
        self.timeout = timeout

    def run(self, deck: str) -> SimResult:
        exe = shutil.which(self.executable)
        if exe is None:
            raise SimulatorError(f"ngspice is not installed ({self.executable!r} not found); {INSTALL_HINT}")
        with tempfile.TemporaryDirectory(prefix=lifetime.owned_prefix("sim")) as tmp:
            raw_path = Path(tmp) / "out.raw"
            _, log, errs = self._batch(exe, tmp, with_raw_output(deck, raw_path))
            if not raw_path.exists() or raw_path.stat().st_size == 0:
                raise SimulatorError("ngspice exited without writing any results"
                                     + (f" ({'; '.join(errs[:3])})" if errs else " (no analysis ran?)"))
            vectors = read_raw(raw_path)
            if "time" not in vectors and "frequency" not in vectors:
                raise SimulatorError("ngspice ran no analysis: the deck has no .tran or .ac line")
            return _result(vectors, log, self.name, deck)

    def run_script(self, circuit: str, commands) -> str:
        """``circuit`` (a deck without analyses) with a ``.control`` block of ``commands``
        (``alter``, ``tran``, ``meas``...: a Monte Carlo's loop) in one ``ngspice -b``; its stdout."""
        exe = shutil.which(self.executable)
        if exe is None:
            raise SimulatorError(f"ngspice is not installed ({self.executable!r} not found); {INSTALL_HINT}")
        lines = circuit.rstrip().splitlines()
        if lines and lines[-1].strip().lower() == ".end":
            lines = lines[:-1]
        text = "\n".join([*lines, ".control", "set noaskquit", *commands, "quit", ".endc", ".end"]) + "\n"
        with tempfile.TemporaryDirectory(prefix=lifetime.owned_prefix("sim")) as tmp:
            return self._batch(exe, tmp, text)[0].stdout

    def _batch(self, exe: str, tmp: str, text: str) -> tuple:
        """``ngspice -b`` of the deck ``text`` in the private folder ``tmp``: (process, log, error lines),
        the errors a failed run reports raised (a deck it cannot read, a crash, a failure)."""
        deck_path = Path(tmp) / "deck.cir"
        deck_path.write_text(text)
        try:
            # -n: no .spiceinit; the private folder as working folder and HOME: no init file of anyone's
            proc = subprocess.run([exe, "-b", "-n", str(deck_path)], cwd=tmp, env=private_env(tmp),
                                  capture_output=True, text=True, timeout=self.timeout,
                                  stdin=subprocess.DEVNULL, preexec_fn=lifetime.preexec())
        except subprocess.TimeoutExpired:
            raise SimulatorError(f"ngspice did not finish within {self.timeout:g} s (timed out)") from None
        log = proc.stdout + "\n" + proc.stderr
        errs = error_lines(log) or [ln for ln in proc.stderr.splitlines() if ln.strip()][-1:]
        if deck_refused(log):
            raise DeckError("ngspice cannot read the deck: " + "; ".join(errs[:3]))
        if proc.returncode < 0:
            raise SimulatorError(f"ngspice crashed (signal {-proc.returncode})"
                                 + (f": {'; '.join(errs[:3])}" if errs else ""))
        if proc.returncode != 0:
            raise SimulatorError("ngspice failed: " + ("; ".join(errs[:3]) or f"exit status {proc.returncode}"))
        return proc, log, errs


class PySpiceShared:
    """ngspice as a shared library through PySpice.

    PySpice's own ``run``/``exec_command`` raise on any stderr output, which
    ngspice uses for harmless notes; commands go straight to the library and
    the output is checked here instead.
    """

    name = "pyspice"
    _lock = threading.Lock()  # one shared ngspice instance per process

    def run(self, deck: str) -> SimResult:
        with self._lock:
            ng = shared_instance()
            old = os.getcwd()
            tmp = tempfile.mkdtemp(prefix=lifetime.owned_prefix("sim"))
            try:
                os.chdir(tmp)   # whatever ngspice writes lands in a private folder, removed after
                load_log = self._load(ng, deck)
                log = self._command(ng, "run")
                errs = error_lines(log)
                plot = ng.last_plot
                if errs or not plot.startswith(("tran", "ac")):
                    raise SimulatorError("ngspice failed: " + "; ".join(errs[:3]) if errs else
                                         "ngspice ran no analysis: the deck has no .tran or .ac line")
                # a transient's vectors are real; an .ac run's are complex (frequency included: keep
                # it real, as the raw file reader of the other backend gives it)
                vectors = {name: (np.asarray(vec._data) if plot.startswith("ac") else np.real(vec._data))
                           for name, vec in ng.plot(None, plot).items()}
            finally:
                os.chdir(old)
                shutil.rmtree(tmp, ignore_errors=True)
        return _result(vectors, load_log + "\n" + log, self.name, deck)

    def _load(self, ng, deck: str) -> str:
        """Load ``deck`` as the one circuit of the library (the last one destroyed); its log."""
        self._command(ng, "destroy all")
        self._command(ng, "reset")
        ng.clear_output()
        lines = [ln for ln in deck.splitlines() if ln.strip()] + [""]
        from PySpice.Spice.NgSpice.Shared import FFI, ffi
        keep = [ffi.new("char[]", ln.encode("utf8")) for ln in lines] + [FFI.NULL]
        with lifetime.native():
            rc = ng._ngspice_shared.ngSpice_Circ(ffi.new("char *[]", keep))
        load_log = ng.stdout + "\n" + ng.stderr
        errs = error_lines(load_log)
        if rc or errs:
            why = "; ".join(errs[:3]) or f"code {rc}"
            if deck_refused(load_log):
                raise DeckError("ngspice cannot read the deck: " + why)
            raise SimulatorError("ngspice failed to load the deck: " + why)
        return load_log

    def run_script(self, circuit: str, commands) -> str:
        """Load ``circuit`` (a deck without analyses) once and send it ``commands`` one by one
        (``alter``, ``tran``, ``meas``...: a Monte Carlo's loop); ngspice's output (stdout)."""
        with self._lock:
            ng = shared_instance()
            old = os.getcwd()
            tmp = tempfile.mkdtemp(prefix=lifetime.owned_prefix("sim"))
            out = []
            try:
                os.chdir(tmp)
                self._load(ng, circuit)
                ng.clear_output()
                for cmd in commands:
                    with lifetime.native():
                        ng._ngspice_shared.ngSpice_Command(cmd.encode("ascii"))
                    if len(ng._stdout) > 4096:      # bound the callback's buffer on long loops
                        out.append(ng.stdout)
                        ng.clear_output()
                out.append(ng.stdout)
                self._command(ng, "destroy all")
            finally:
                os.chdir(old)
                shutil.rmtree(tmp, ignore_errors=True)
        return "\n".join(out)

    @staticmethod
    def _command(ng, command: str) -> str:
        ng.clear_output()
        with lifetime.native():
            ng._ngspice_shared.ngSpice_Command(command.encode("ascii"))
        return ng.stdout + "\n" + ng.stderr


def private_env(folder) -> dict:
    """The environment of an ``ngspice -b`` run: ours, with ``HOME`` in its private folder
    (ngspice reads ``~/.spiceinit``; ``-n`` skips it too: both, in case one is ignored).

    Parameters
    ----------
    folder : path-like
        The run's private folder.

    Returns
    -------
    dict
        The environment variables.
    """
    env = dict(os.environ)
    env["HOME"] = str(folder)
    return env


def shared_instance():
    """PySpice's one ngspice shared library instance, started (the first time) in a
    private empty folder with ``HOME`` pointing there, so that the library reads no
    user's ``.spiceinit``; a :class:`SimulatorError` when it cannot be loaded."""
    try:
        from PySpice.Spice.NgSpice.Shared import NgSpiceShared
    except ImportError as exc:  # pragma: no cover - dependency of the package
        raise SimulatorError(f"PySpice is not installed: {exc}") from None
    import logging
    logging.getLogger("PySpice").setLevel(logging.CRITICAL)   # its "unsupported version" notes
    if getattr(NgSpiceShared, "_designer_started", False):
        return NgSpiceShared.new_instance()
    old, home = os.getcwd(), os.environ.get("HOME")
    with tempfile.TemporaryDirectory(prefix=lifetime.owned_prefix("init")) as tmp:
        try:
            os.chdir(tmp)
            os.environ["HOME"] = tmp
            with lifetime.native():
                ng = NgSpiceShared.new_instance()
        except Exception as exc:   # OSError, or PySpice's own on a broken library
            raise SimulatorError(f"cannot load the ngspice shared library ({exc}); {INSTALL_HINT}") from None
        finally:
            os.chdir(old)
            if home is None:
                os.environ.pop("HOME", None)
            else:
                os.environ["HOME"] = home
    NgSpiceShared._designer_started = True
    return ng


#: the longest one simulation may take, seconds (``ngspice -b``; the shared library runs in the caller's
#: process: ``check-design`` runs it in a worker it kills at the same deadline)
DEFAULT_TIMEOUT_S = 120.0


def get_simulator(name: str = "pyspice", timeout: float | None = None):
    """A backend by name: ``pyspice`` or ``ngspice-cli``; ``timeout`` (seconds)
    bounds each ``ngspice -b`` run (default :data:`DEFAULT_TIMEOUT_S`).

    Parameters
    ----------
    name : str
        ``pyspice`` (also ``shared``, ``ngspice-shared``) or ``ngspice-cli`` (also ``cli``, ``ngspice``).
    timeout : float or None
        Seconds each ``ngspice -b`` run may take; None: :data:`DEFAULT_TIMEOUT_S`.

    Returns
    -------
    PySpiceShared or NgspiceCli
        The backend; an unknown name is a :class:`~designer.core.errors.DesignError`.
    """
    key = str(name).strip().lower()
    if key in ("pyspice", "shared", "ngspice-shared"):
        return PySpiceShared()
    if key in ("ngspice-cli", "cli", "ngspice"):
        return NgspiceCli(timeout=DEFAULT_TIMEOUT_S if timeout is None else timeout)
    raise DesignError(f"unknown simulator {name!r}; allowed: {', '.join(BACKENDS)}")


_VERSIONS: dict = {}


def ngspice_version(simulator: str | None) -> str | None:
    """The version of ngspice behind a backend (``"39"``; the shared library
    and the program can differ), None when it cannot be told. Asked once per
    process and backend.

    Parameters
    ----------
    simulator : str or None
        The backend's name (:func:`get_simulator`); None: no simulation.

    Returns
    -------
    str or None
        The version.
    """
    if simulator is None:
        return None
    key = get_simulator(simulator).name
    if key not in _VERSIONS:
        _VERSIONS[key] = _shared_version() if key == "pyspice" else _cli_version()
    return _VERSIONS[key]


def _cli_version() -> str | None:
    exe = shutil.which("ngspice")
    if exe is None:
        return None
    try:
        out = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=30,
                             stdin=subprocess.DEVNULL).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    m = re.search(r"ngspice-(\S+)", out)
    return m.group(1) if m else None


def _shared_version() -> str | None:
    try:
        with PySpiceShared._lock:
            version = shared_instance().ngspice_version
    except Exception:   # no library, or PySpice could not ask it: unknown, not an error
        return None
    return None if version is None else str(version)


#: the command line the results made in this context record, when it is not this process's own (the web
#: page's request stands for one: a record, never parsed); None: ``sys.argv``
_COMMAND = contextvars.ContextVar("recorded_command", default=None)


@contextmanager
def recorded_command(argv):
    """``with recorded_command(argv):`` the results made in the block record ``argv`` as their command line
    (:func:`tool_info`'s default) instead of this process's ``sys.argv``, which stays untouched (the web
    page's check job once swapped ``sys.argv`` itself, a global of the whole worker).

    Parameters
    ----------
    argv : list of str
        The command line recorded.

    Yields
    ------
    None
    """
    token = _COMMAND.set(list(argv))
    try:
        yield
    finally:
        _COMMAND.reset(token)


def tool_info(simulator: str | None, argv=None) -> dict:
    """What produced a result, for ``result.json``'s ``tool`` and the JUnit
    properties: this tool's name and version, Python's, ngspice's (None
    without a simulation) and the backend, and the command line.

    Parameters
    ----------
    simulator : str or None
        The backend's name; None: no simulation.
    argv : list of str, optional
        The command line; default the one :func:`recorded_command` set, else ``sys.argv``.

    Returns
    -------
    dict
        ``name``, ``version``, ``python``, ``ngspice``, ``simulator`` and ``argv``.
    """
    from .. import __version__
    if argv is None:
        argv = _COMMAND.get()
    return {"name": "designer", "version": __version__, "python": sys.version.split()[0],
            "ngspice": ngspice_version(simulator), "simulator": simulator,
            "argv": list(sys.argv if argv is None else argv)}
