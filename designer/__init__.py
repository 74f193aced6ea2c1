"""Analog design-and-verification toolkit: Sallen-Key plants, op-amp PID
controllers, ngspice verification and classical identification."""

__version__ = "0.1.0"
