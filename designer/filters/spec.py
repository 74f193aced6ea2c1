"""What a filter is asked to be: :class:`FilterSpec`, checked once when built
(every refusal one line naming the input and its range or the allowed words).

Either an order and a cut-off, or a mask (passband edge and its largest loss,
stopband edge and its least attenuation) that picks the order (scipy.signal's
``buttord``/``cheb1ord``; Bessel by search, :func:`~designer.filters.prototype.order_from_mask`).
The cut-off's meaning is stated and selectable because the literature mixes
them (TI SLOA088 tabulates the Bessel at -3 dB and the Chebyshev at its
ripple edge, Zverev normalises the Bessel to its delay): ``bessel_norm``
``mag`` (-3 dB at fc) or ``delay`` (group delay 1/(2 pi fc) at DC), and
``chebyshev_cutoff`` ``ripple`` (fc the ripple edge) or ``3db``.

``gain`` is the passband gain: at DC for a low-pass, at high frequency for a
high-pass (an even-order Chebyshev then peaks ``ripple_db`` above it).
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass

from ..core import opamps
from ..core.errors import DesignError, ParamError
from ..core.i18n import gettext as _
from ..core.eseries import PartBounds
from ..core.ranges import RANGES, parse_in_range
from ..core.units import format_eng
from .prototype import BANDPASS_METHODS, BESSEL_NORMS, CHEBYSHEV_CUTOFFS, FAMILIES, RESPONSE_TYPES

__all__ = ["TOPOLOGY_CHOICES", "FilterSpec"]

#: the section families a stage may use; ``auto`` takes Sallen-Key and falls back to MFB
TOPOLOGY_CHOICES = ("sallen-key", "mfb", "auto")


def _word(value, allowed: tuple, name: str) -> str:
    key = str(value).strip().lower()
    if key not in allowed:
        close = difflib.get_close_matches(key, allowed, n=1, cutoff=0.0)
        hint = f"; did you mean {close[0]}?" if close else ""
        raise DesignError(f"{name}: unknown {name} {value!r}; allowed: {', '.join(allowed)}{hint}", param=name)
    return key


@dataclass(frozen=True, kw_only=True)
class FilterSpec(PartBounds):
    """A filter from a specification.

    Parameters
    ----------
    filter_type : str
        ``lowpass``, ``highpass`` or ``bandpass``.
    family : str
        ``butterworth``, ``bessel`` or ``chebyshev``.
    order : int or None
        1..10; None with a mask.
    fc_hz : float or str or None
        Cut-off in the family's convention (engineering notation allowed); None with a mask.
    ripple_db : float
        Chebyshev ripple, 0.01..3 dB (with a mask: the mask's ``max_loss_db``).
    bessel_norm, chebyshev_cutoff : str
        The cut-off conventions (module docstring).
    passband_hz, max_loss_db, stopband_hz, min_attenuation_db : float or None
        The mask, all four or none (low- and high-pass).
    max_delay_error_pct, delay_to_hz : float or None
        A Bessel low-pass's group-delay target, with a mask: the delay within this % of its DC value
        up to ``delay_to_hz``; the least order meeting the mask and the target. Both or none.
    f_low_hz, f_high_hz : float or None
        A band-pass's edges (in the family's cut-off convention), instead of ``fc_hz``.
    bandpass_method : str
        ``auto``, ``wide`` (high-pass then low-pass) or ``narrow`` (band-pass sections).
    topology : str or tuple of str
        ``sallen-key``, ``mfb`` or ``auto``; a tuple gives one per stage.
    stage_order : tuple of int or None
        The stages (numbered 1.. in rising Q) in the order to build them; None: rising Q.
    gain : float
        Passband gain magnitude, 1..100 V/V.
    stage_gains : tuple of float or None
        Each stage's gain in build order, 1..100 V/V each, their product ``gain``; None: split by the design.
    opamp : str
        Catalogue name (:mod:`designer.core.opamps`).
    amplitude_v : float
        The bench's input amplitude (peak volts): no node may clip at it.
    gbw_margin : float
        Required GBW = margin x fn x Q x noise gain per stage (TI's rule of thumb: 100).
    impedance_ohm : float
        The resistor scale of the synthesis.
    compensate_gbw : bool
        Pre-distort each stage's fn and Q for its op-amp's finite gain and GBW.
    r_series, c_series, r_min, r_max, c_min, c_max
        Part series and bounds (:class:`~designer.core.eseries.PartBounds`).
    """

    filter_type: str = "lowpass"
    family: str = "butterworth"
    order: int | None = None
    fc_hz: float | None = None
    ripple_db: float | None = None
    bessel_norm: str = "mag"
    chebyshev_cutoff: str = "ripple"
    passband_hz: float | None = None
    max_loss_db: float | None = None
    stopband_hz: float | None = None
    min_attenuation_db: float | None = None
    max_delay_error_pct: float | None = None
    delay_to_hz: float | None = None
    f_low_hz: float | None = None
    f_high_hz: float | None = None
    bandpass_method: str = "auto"
    topology: object = "sallen-key"
    stage_order: tuple | None = None
    gain: float = 1.0
    stage_gains: tuple | None = None
    opamp: str = "LM741"
    amplitude_v: float = 1.0
    gbw_margin: float = 100.0
    impedance_ohm: float = 10e3
    compensate_gbw: bool = False

    def __post_init__(self):
        self.check_bounds()
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731  (frozen: set once, here)
        put("filter_type", _word(self.filter_type, RESPONSE_TYPES, "filter_type"))
        put("family", _word(self.family, FAMILIES, "family"))
        put("bessel_norm", _word(self.bessel_norm, BESSEL_NORMS, "bessel_norm"))
        put("chebyshev_cutoff", _word(self.chebyshev_cutoff, CHEBYSHEV_CUTOFFS, "chebyshev_cutoff"))
        topo = self.topology
        parts = tuple(str(topo).split(",")) if isinstance(topo, str) else tuple(topo)
        put("topology", tuple(_word(t, TOPOLOGY_CHOICES, "topology") for t in parts))
        for name, key in (("gain", "gain"), ("amplitude_v", "amplitude_v"), ("gbw_margin", "gbw_margin"),
                          ("impedance_ohm", "impedance_ohm")):
            put(name, parse_in_range(getattr(self, name), name, key))
        opamps.get(self.opamp)
        mask = {k: getattr(self, k) for k in ("passband_hz", "max_loss_db", "stopband_hz", "min_attenuation_db")}
        given = [k for k, v in mask.items() if v is not None]
        put("bandpass_method", _word(self.bandpass_method, BANDPASS_METHODS, "bandpass_method"))
        if self.filter_type == "bandpass":
            self._check_band(given)
        elif self.f_low_hz is not None or self.f_high_hz is not None:
            raise DesignError(f"f_low_hz: band edges are for a bandpass; a {self.filter_type} takes fc_hz",
                              param="f_low_hz")
        elif given:
            self._check_mask(mask, given)
        else:
            if self.order is None or self.fc_hz is None:
                raise DesignError("order: give --order and --fc, or the mask (--passband, --max-loss, --stopband, "
                                  "--min-attenuation) that picks them", param="order")
            put("fc_hz", parse_in_range(self.fc_hz, "fc_hz", "fc_hz"))
        if self.order is not None:
            order = parse_in_range(self.order, "order", "filter_order")
            if order != int(order):
                raise DesignError(f"order must be a whole number 1 to 10, got {self.order!r}", param="order")
            put("order", int(order))
        if self.family == "chebyshev":
            rip = self.ripple_db if self.ripple_db is not None else (self.max_loss_db if given else 1.0)
            if self.ripple_db is None and given and not RANGES["ripple_db"].contains(rip):
                # the ripple was not given: the mask's loss is, so the refusal names the loss
                raise DesignError(f"max_loss_db: a chebyshev mask's passband loss is its ripple, which must be "
                                  f"{RANGES['ripple_db'].text()}, got {rip:g} dB; allow less loss, or use "
                                  "butterworth or bessel", param="max_loss_db")
            put("ripple_db", parse_in_range(rip, "ripple_db", "ripple_db"))
        elif self.ripple_db is not None:
            raise DesignError(f"ripple_db: only a chebyshev filter has a ripple ({self.family} asked)",
                              param="ripple_db")
        if self.stage_order is not None:
            so = self.stage_order
            items = str(so).split(",") if isinstance(so, str) else list(so)
            try:
                put("stage_order", tuple(int(str(x).strip()) for x in items))
            except ValueError:
                raise DesignError(f"stage_order must be stage numbers such as 2,1,3, got {so!r}",
                                  param="stage_order") from None
        if self.stage_gains is not None:
            self._check_stage_gains()
        if self.max_delay_error_pct is not None or self.delay_to_hz is not None:
            self._check_delay_target(given)

    def _check_delay_target(self, given: list) -> None:
        """A group-delay flatness target: a Bessel low-pass's, with a mask, both numbers."""
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        if self.family != "bessel":
            raise DesignError(f"max_delay_error_pct: a group-delay target is for a bessel filter (the flat-delay "
                              f"family); a {self.family}'s delay is not flat", param="max_delay_error_pct")
        if self.filter_type != "lowpass":
            raise DesignError(f"max_delay_error_pct: a group-delay target is for a lowpass (its delay at DC); a "
                              f"{self.filter_type} has none", param="max_delay_error_pct")
        if not given:
            raise DesignError("max_delay_error_pct: a group-delay target joins a mask in picking the order; give "
                              "--passband, --max-loss, --stopband and --min-attenuation too", param="max_delay_error_pct")
        missing = [k for k in ("max_delay_error_pct", "delay_to_hz") if getattr(self, k) is None]
        if missing:
            raise DesignError(f"{missing[0]}: a group-delay target needs both max_delay_error_pct and delay_to_hz",
                              param=missing[0])
        put("max_delay_error_pct", parse_in_range(self.max_delay_error_pct, "max_delay_error_pct",
                                                  "max_delay_error_pct"))
        put("delay_to_hz", parse_in_range(self.delay_to_hz, "delay_to_hz", "fc_hz"))

    @property
    def has_delay_target(self) -> bool:
        """Whether a group-delay flatness target was given."""
        return self.max_delay_error_pct is not None

    def _check_stage_gains(self) -> None:
        sg = self.stage_gains
        items = str(sg).split(",") if isinstance(sg, str) else list(sg)
        gains = tuple(parse_in_range(str(x).strip(), "stage_gains", "gain") for x in items)
        product = math.prod(gains)
        if not math.isclose(product, self.gain, rel_tol=1e-9):
            shown = " x ".join(f"{g:g}" for g in gains)
            raise ParamError(f"{{stage_gains}}: {shown} = {product:.6g} is not {{gain}} {self.gain:g}; give stage "
                             "gains whose product is the passband gain")
        object.__setattr__(self, "stage_gains", gains)

    def _check_band(self, given: list) -> None:
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        if given:
            self._check_band_mask(given)
            return
        if self.fc_hz is not None:
            raise DesignError("fc_hz: a bandpass takes its edges f_low_hz and f_high_hz, not fc_hz", param="fc_hz")
        if self.order is None or self.f_low_hz is None or self.f_high_hz is None:
            raise DesignError("order: a bandpass needs --order, --f-low and --f-high", param="order")
        for k in ("f_low_hz", "f_high_hz"):
            put(k, parse_in_range(getattr(self, k), k, "fc_hz"))
        if self.f_low_hz >= self.f_high_hz:
            raise ParamError(f"the band's edges cross: {{f_low_hz}} ({self.f_low_hz:g} Hz) is not below "
                             f"{{f_high_hz}} ({self.f_high_hz:g} Hz)")

    def _check_band_mask(self, given: list) -> None:
        """A band-pass's mask: two passband edges inside two stopband edges; the order, the band edges
        and the wide or narrow split picked from it (:func:`~designer.filters.prototype.bandpass_from_mask`)."""
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        mask = {k: getattr(self, k) for k in ("passband_hz", "max_loss_db", "stopband_hz", "min_attenuation_db")}
        missing = [k for k, v in mask.items() if v is None]
        if missing:
            raise DesignError(f"{missing[0]}: a band-pass mask needs all of passband_hz, max_loss_db, stopband_hz "
                              f"and min_attenuation_db; missing {', '.join(missing)}", param=missing[0])
        for k in ("order", "fc_hz", "f_low_hz", "f_high_hz"):
            if getattr(self, k) is not None:
                raise DesignError(f"{k}: give either a band-pass's order and edges or its mask, not both (the mask "
                                  "picks them)", param=k)
        for k in ("passband_hz", "stopband_hz"):
            put(k, _edge_pair(getattr(self, k), k))
        for k in ("max_loss_db", "min_attenuation_db"):
            put(k, parse_in_range(getattr(self, k), k, k))
        self._check_ripple_is_loss()
        (p1, p2), (s1, s2) = self.passband_hz, self.stopband_hz
        if not (s1 < p1 and s2 > p2):
            raise ParamError(f"the stopband is not outside the passband: {{stopband_hz}} ({s1:g}, {s2:g} Hz) must "
                             f"have its low edge below {p1:g} Hz and its high edge above {p2:g} Hz ({{passband_hz}})")
        self._check_attenuation()
        from .prototype import bandpass_from_mask   # scipy.signal: only when a band-pass mask asks for it
        order, f_low, f_high, method = bandpass_from_mask(
            self.family, self.passband_hz, self.max_loss_db, self.stopband_hz, self.min_attenuation_db,
            self.bessel_norm, self.chebyshev_cutoff, self.bandpass_method)
        put("order", order)
        put("f_low_hz", f_low)
        put("f_high_hz", f_high)
        put("bandpass_method", method)

    def _check_ripple_is_loss(self) -> None:
        if self.family == "chebyshev" and self.ripple_db is not None and \
                not math.isclose(float(self.ripple_db), self.max_loss_db):
            raise DesignError("ripple_db: with a mask the chebyshev ripple is the mask's max_loss_db; leave "
                              "--ripple out", param="ripple_db")

    def _check_attenuation(self) -> None:
        if self.min_attenuation_db <= self.max_loss_db:
            raise DesignError(f"min_attenuation_db ({self.min_attenuation_db:g} dB) must exceed max_loss_db "
                              f"({self.max_loss_db:g} dB)", param="min_attenuation_db")

    def _check_mask(self, mask: dict, given: list) -> None:
        missing = [k for k, v in mask.items() if v is None]
        if missing:
            raise DesignError(f"{missing[0]}: a mask needs all of passband_hz, max_loss_db, stopband_hz and "
                              f"min_attenuation_db; missing {', '.join(missing)}", param=missing[0])
        if self.order is not None or self.fc_hz is not None:
            raise DesignError("order: give either --order and --fc or a mask, not both (the mask picks them)",
                              param="order")
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        for k in ("passband_hz", "stopband_hz"):
            v = getattr(self, k)
            if isinstance(v, (list, tuple)) or (isinstance(v, str) and "," in v):
                raise DesignError(f"{k}: two edges F1,F2 are for a bandpass; a {self.filter_type} takes one",
                                  param=k)
            put(k, parse_in_range(v, k, "fc_hz"))
        for k in ("max_loss_db", "min_attenuation_db"):
            put(k, parse_in_range(getattr(self, k), k, k))
        self._check_ripple_is_loss()
        low = self.filter_type == "lowpass"
        if (self.passband_hz >= self.stopband_hz) == low:
            need = "below" if low else "above"
            raise DesignError(f"stopband_hz: a {self.filter_type}'s passband edge ({self.passband_hz:g} Hz) must be "
                              f"{need} its stopband edge ({self.stopband_hz:g} Hz)", param="stopband_hz")
        self._check_attenuation()

    @property
    def has_mask(self) -> bool:
        """Whether a mask (rather than an order) was given."""
        return self.passband_hz is not None

    @property
    def passband_edges(self) -> tuple:
        """The mask's passband edges, Hz: one for a low- or high-pass, (low, high) for a band-pass; () without a mask."""
        return _as_tuple(self.passband_hz)

    @property
    def stopband_edges(self) -> tuple:
        """The mask's stopband edges, Hz, as :attr:`passband_edges`."""
        return _as_tuple(self.stopband_hz)

    def mask_phrases(self) -> tuple:
        """Where the mask's loss and attenuation hold, in words (the current language's, :mod:`designer.core.i18n`).

        Returns
        -------
        tuple of str
            (passband, stopband): ``to 1 kHz``, ``from 3 kHz`` for a low- or high-pass;
            ``from 900 Hz to 1.1 kHz``, ``below 600 Hz and above 1.7 kHz`` for a band-pass.
        """
        hz = lambda v: format_eng(v, "Hz")  # noqa: E731
        if self.filter_type == "bandpass":
            (p1, p2), (s1, s2) = self.passband_edges, self.stopband_edges
            return (_("from {low} to {high}").format(low=hz(p1), high=hz(p2)),
                    _("below {low} and above {high}").format(low=hz(s1), high=hz(s2)))
        return _("to {f}").format(f=hz(self.passband_hz)), _("from {f}").format(f=hz(self.stopband_hz))


def _as_tuple(v) -> tuple:
    return () if v is None else tuple(v) if isinstance(v, (tuple, list)) else (v,)


def _edge_pair(value, name: str) -> tuple:
    """A band-pass mask's two edges ``F1,F2`` (engineering notation, each in fc_hz's range), rising."""
    items = str(value).split(",") if isinstance(value, str) else list(value) if isinstance(value, (list, tuple)) \
        else [value]
    if len(items) != 2:
        raise DesignError(f"{name}: a band-pass mask takes two edges F1,F2 (such as 1k,2k), got {value!r}",
                          param=name)
    lo, hi = (parse_in_range(str(x).strip() if isinstance(x, str) else x, name, "fc_hz") for x in items)
    if lo >= hi:
        raise ParamError(f"{{{name}}}'s edges cross: {lo:g} Hz is not below {hi:g} Hz; give the low edge first")
    return lo, hi
