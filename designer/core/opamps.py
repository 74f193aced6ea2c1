"""A small op-amp catalogue (data in ``data/opamps.json``) and the single-pole
op-amp model that both the analytic models and the SPICE subcircuit use.

The model: A(s) = A0 / (1 + s / wp) with wp = 2 pi GBW / A0, a slew-rate
limit, and an output that stays ``swing_*`` volts inside the rails.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

from .errors import DesignError


@dataclass(frozen=True)
class OpAmp:
    """Datasheet-typical figures of one op-amp."""

    name: str
    description: str
    a0: float            #: DC open-loop gain (V/V)
    gbw_hz: float        #: gain-bandwidth product (Hz)
    slew_v_per_s: float  #: slew rate (V/s)
    vcc: float           #: positive supply (V)
    vee: float           #: negative supply (V)
    swing_high_v: float  #: output headroom below vcc (V)
    swing_low_v: float   #: output headroom above vee (V)
    ideal: bool = False
    pins: dict | None = None  #: DIP-8 pin numbers (out, inn, inp, vcc, vee) and package

    @property
    def vout_max(self) -> float:
        return self.vcc - self.swing_high_v

    @property
    def vout_min(self) -> float:
        return self.vee + self.swing_low_v

    @property
    def pole_hz(self) -> float:
        """Open-loop dominant pole, GBW / A0."""
        return self.gbw_hz / self.a0

    def to_dict(self) -> dict:
        """The op-amp as every result's JSON gives it: the figures a design used."""
        return {"name": self.name, "gbw_hz": self.gbw_hz, "slew_v_per_s": self.slew_v_per_s, "a0": self.a0,
                "vcc": self.vcc, "vee": self.vee, "vout_max": self.vout_max, "vout_min": self.vout_min}


@lru_cache(maxsize=1)
def _catalogue() -> dict:
    text = resources.files("designer.core").joinpath("data/opamps.json").read_text()
    raw = json.loads(text)
    return {name: OpAmp(name=name, ideal=spec.pop("ideal", False), **spec)
            for name, spec in ((k, dict(v)) for k, v in raw.items() if not k.startswith("_"))}


def names() -> list:
    """Catalogue names, as ``--opamp`` accepts them."""
    return list(_catalogue())


def get(name: str) -> OpAmp:
    """Look up an op-amp by name (case-insensitive)."""
    for key, amp in _catalogue().items():
        if key.lower() == str(name).strip().lower():
            return amp
    raise DesignError(f"unknown op-amp {name!r}; allowed: {', '.join(names())}")
