"""What a ``design-plant`` or ``analyze-plant`` user asks for, validated once,
when it is built.

A :class:`PlantSpec` (a design) or an :class:`AnalysisSpec` (parts as built)
that exists is a valid one: every number inside its physical range
(:data:`designer.core.ranges.RANGES`), the options consistent, the series
names normalised, the op-amp in the catalogue and, for parts as built, the
circuit a stable plant (:func:`designer.plant.sallenkey.check_parts`).
Numbers may be given as numbers or as text in engineering notation
(``"3.5k"``), so that the command line hands over what the user typed and a
refusal quotes it.

Errors name the library's parameters (``fc_hz``, ``r_min``); the command line
shows its options instead (``--fc``, ``--r-min``) from one table,
:data:`designer.cli.common.FLAGS`.

The target is the seed's (001, IV.3-IV.9): T(s) = K wn^2 / (s^2 + 2 zeta wn s +
wn^2) with fn = wn / 2 pi, realised by a Sallen-Key low-pass of gain K.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core import opamps
from ..core.errors import DesignError, ParamError
from ..core.eseries import PartBounds, series_name
from ..core.opamps import OpAmp
from ..core.ranges import RANGES, parse_in_range
from ..filters import registry
from ..filters.sallen_key_lowpass_parts import FIELD_OF
from .circuit import DEFAULT_TOPOLOGY, plant_target
from .sallenkey import SallenKeyParts, check_parts

__all__ = ["AnalysisSpec", "PlantSpec"]


def _check_bench(spec, put) -> None:
    """The op-amp (and the package the sheet wires it in) and the bench's square
    wave, as both specs have them."""
    put("amplitude_v", parse_in_range(spec.amplitude_v, "amplitude_v", "amplitude_v"))
    if spec.square_hz is not None:
        put("square_hz", parse_in_range(spec.square_hz, "square_hz", "square_hz"))
    put("opamp", opamps.get(spec.opamp).name)
    if spec.package is not None:
        opamps.get(spec.opamp).package(spec.package)   # refused when the op-amp does not come in it


def _whole(value, name: str) -> int:
    """``value`` (a number or text) as a whole number inside ``RANGES[name]``."""
    try:
        n = parse_in_range(value, name, name)
        if n == int(n):
            return int(n)
    except DesignError:
        pass
    if isinstance(value, str):
        shown = repr(value)
    elif isinstance(value, (int, float)):
        shown = f"{value:g}"
    else:
        shown = type(value).__name__
    raise DesignError(f"{name} must be a whole number from {RANGES[name].text()}, got {shown}", param=name)


def _setter(spec):
    def put(name, value):
        object.__setattr__(spec, name, value)   # frozen: the spec is normalised once, in __post_init__
    return put


@dataclass(frozen=True)
class PlantSpec(PartBounds):
    """A plant design request (SI units), validated on construction.

    ``fc_hz``, ``zeta`` and ``gain`` are the target; the parts come from the
    series and bounds of :class:`~designer.core.eseries.PartBounds`
    (keyword-only), or, with ``r`` and ``c`` together, from the seed's
    procedure (fix R and C, solve m and n). ``opamp`` names the op-amp the
    design is verified with (``compensate_gbw`` aims the design off so that
    its finite gain-bandwidth lands it on the target); ``amplitude_v`` and
    ``square_hz`` set the bench's square wave (default frequency: see
    :func:`designer.plant.bench.recommend_square_wave`); ``alternatives`` is how
    many best combinations the result lists. ``topology`` names the registered
    section that realises the plant (:mod:`designer.filters.registry`; default
    the seed's Sallen-Key low-pass); with ``r`` and ``c`` another section takes the
    seed's procedure through its
    :meth:`~designer.filters.topology.Topology.synthesize_rc` (which refuses, at
    design time, an R and C the section cannot take); a first-order section takes
    no ``zeta`` (None).

    Raises
    ------
    DesignError
        One line naming the parameter at fault and what is allowed.
    """

    fc_hz: float
    zeta: float
    gain: float = 1.0
    r: float | None = None        #: the seed's procedure: fix R ...
    c: float | None = None        #: ... and C, solve m and n
    opamp: str = "LM741"
    compensate_gbw: bool = False
    amplitude_v: float = 2.0
    square_hz: float | None = None
    alternatives: int = 5
    package: str | None = None    #: single, dual, quad for the sheet's wiring (None: the op-amp's first)
    topology: str = DEFAULT_TOPOLOGY

    def __post_init__(self):
        put = _setter(self)
        topo = registry.get(self.topology)
        put("topology", topo.name)
        for name in ("fc_hz", "zeta", "gain"):
            if name == "zeta" and topo.order == 1 and self.zeta is None:
                continue
            put(name, parse_in_range(getattr(self, name), name, name))
        plant_target(topo, self.fc_hz, self.zeta, self.gain)   # a damping for a first-order section refused
        self.check_bounds()
        if (self.r is None) != (self.c is None):
            raise ParamError("{r} and {c} go together (the seed's procedure fixes both R and C)")
        if self.r is not None:
            put("r", parse_in_range(self.r, "r", "resistor_ohm"))
            put("c", parse_in_range(self.c, "c", "capacitor_f"))
        put("alternatives", _whole(self.alternatives, "alternatives"))
        _check_bench(self, put)

    @property
    def amp(self) -> OpAmp:
        """The op-amp, from the catalogue."""
        return opamps.get(self.opamp)


#: the parts' fields as the plant check names them: markers of a ParamError
_PART_NAMES = {k: f"{{{k}}}" for k in (*FIELD_OF.values(), "gain")}


@dataclass(frozen=True)
class AnalysisSpec:
    """An analysis request for parts as built (e.g. the seed's rounded
    820/1k/10n/220n), validated on construction.

    ``parts`` go through :func:`~designer.plant.sallenkey.check_parts` (values
    as numbers or engineering notation; a bare gain K > 1 gets its R3/R4
    there); ``target_fc_hz``/``target_zeta``, optional, are what the errors
    are reported against; ``r_series``/``c_series`` say where the parts come
    from, for their tolerance (None: each part is labelled with the smallest
    series that holds its value). The op-amp and square wave as for
    :class:`PlantSpec`.

    Raises
    ------
    DesignError
        One line naming the parameter at fault (``r1``, ``target_fc_hz``) and
        what is allowed.
    """

    parts: SallenKeyParts
    opamp: str = "LM741"
    target_fc_hz: float | None = None
    target_zeta: float | None = None
    r_series: str | None = None
    c_series: str | None = None
    amplitude_v: float = 2.0
    square_hz: float | None = None
    package: str | None = None

    def __post_init__(self):
        put = _setter(self)
        try:
            put("parts", check_parts(self.parts, name_of=_PART_NAMES, text=True))
        except DesignError as exc:
            raise ParamError(str(exc), params=_PART_NAMES) from None
        for name, key in (("target_fc_hz", "fc_hz"), ("target_zeta", "zeta")):
            if getattr(self, name) is not None:
                put(name, parse_in_range(getattr(self, name), name, key))
        for name in ("r_series", "c_series"):
            if getattr(self, name) is not None:
                put(name, series_name(getattr(self, name)))
        _check_bench(self, put)

    @property
    def amp(self) -> OpAmp:
        """The op-amp, from the catalogue."""
        return opamps.get(self.opamp)
