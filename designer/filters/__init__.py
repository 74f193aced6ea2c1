"""Active-filter sections as plug-ins: the :class:`Topology` abstraction (its
parts declared once, its transfer function vectorised, ideal and with the
op-amp's finite gain, its synthesis, realisability limits and netlist), the
registry of sections (Sallen-Key low- and high-pass, MFB low-, high- and
band-pass, first-order RC and inverting sections) and the :class:`Cascade` of
sections; filters from a specification (:func:`design`: scipy's prototypes,
the gain split, the op-amp check, E-series parts chosen jointly across the
stages, the ngspice proof). Below the wings: it imports ``core`` and ``spice`` only."""

from .cascade import Cascade, Stage
from .deck import ac_deck, simulate_ac
from .design import (FilterDesign, StageDesign, analysis_grid, design, predistort, section_name, stage_candidates,
                     verify_spice)
from .joint import brute_force, descend, joint_search, objective, per_stage
from .prototype import (BANDPASS_METHODS, BESSEL_NORMS, CHEBYSHEV_CUTOFFS, FAMILIES, MAX_ORDER, RESPONSE_TYPES,
                        WIDE_RATIO, SectionPlan, bandpass_method, chebyshev_3db_factor, order_from_mask,
                        plan_bandpass, plan_sections, prototype_zpk, reference_ba, reference_bandpass,
                        reference_response)
from .inverting_lowpass import InvertingLowPass
from .mfb_bandpass import MfbBandPass
from .mfb_highpass import MfbHighPass
from .mfb_lowpass import MfbLowPass
from .rc_highpass import RcHighPass
from .rc_lowpass import RcLowPass
from .registry import REGISTRY, get, names, register
from .sallen_key import GAIN_PARTS, SallenKeySection
from .sallen_key_highpass import SallenKeyHighPass
from .sallen_key_lowpass import SallenKeyLowPass, sallen_key_ratio_min
from .spec import TOPOLOGY_CHOICES, FilterSpec
from .topology import (
    DEFAULT_IMPEDANCE_OHM,
    KINDS,
    Figures,
    PartSpec,
    SectionTarget,
    Topology,
    nodal_response,
    nodal_system,
    open_loop_gain,
    polynomial,
    polyval,
    quadratic_root,
)

__all__ = ["Cascade", "Stage", "ac_deck", "simulate_ac", "FilterDesign", "StageDesign", "analysis_grid", "design", "predistort",
           "section_name", "stage_candidates", "verify_spice", "brute_force", "descend", "joint_search", "objective",
           "per_stage", "BANDPASS_METHODS", "WIDE_RATIO", "bandpass_method", "plan_bandpass", "reference_bandpass",
           "BESSEL_NORMS", "CHEBYSHEV_CUTOFFS", "FAMILIES", "MAX_ORDER", "RESPONSE_TYPES", "SectionPlan",
           "chebyshev_3db_factor", "order_from_mask", "plan_sections", "prototype_zpk", "reference_ba",
           "reference_response", "TOPOLOGY_CHOICES", "FilterSpec", "InvertingLowPass", "MfbBandPass", "MfbHighPass",
           "MfbLowPass", "RcHighPass", "RcLowPass", "REGISTRY", "get", "names", "register", "GAIN_PARTS",
           "SallenKeySection", "SallenKeyHighPass", "SallenKeyLowPass", "sallen_key_ratio_min",
           "DEFAULT_IMPEDANCE_OHM", "KINDS", "Figures", "PartSpec", "SectionTarget", "Topology", "nodal_response", "nodal_system",
           "open_loop_gain", "polynomial", "polyval", "quadratic_root"]
