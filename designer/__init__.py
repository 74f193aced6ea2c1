"""Analog design-and-verification toolkit: Sallen-Key plants, op-amp PID
controllers, ngspice verification and classical identification.

The public API (imported on first use, so that a command pays only for what
it runs)::

    from designer import design_plant, analyze_plant, design_pid, analyze_pid, identify_step, identify_freq

Layout: ``core`` (the domain-free floor), ``spice`` and ``report`` above it,
the three wings ``plant``, ``pid`` and ``identify``, and ``cli`` on top.
"""

__version__ = "0.1.0"

#: public name -> module that defines it
_API = {
    "design_plant": "designer.plant.design", "analyze_plant": "designer.plant.design",
    "PlantSpec": "designer.plant.spec", "AnalysisSpec": "designer.plant.spec",
    "SallenKeyParts": "designer.plant.sallenkey",
    "design_pid": "designer.pid.design", "analyze_pid": "designer.pid.design", "PidSpec": "designer.pid.spec",
    "identify_step": "designer.identify.step", "identify_freq": "designer.identify.frequency",
    "read_capture": "designer.identify.io", "DesignError": "designer.core.errors",
    "identify_output_error": "designer.identify.outputerror",
}

__all__ = ["__version__", *_API]


def __getattr__(name):
    if name in _API:
        import importlib
        return getattr(importlib.import_module(_API[name]), name)
    raise AttributeError(f"module 'designer' has no attribute {name!r}")
