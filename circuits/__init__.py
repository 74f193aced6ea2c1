"""The project's own SPICE model library (no vendor models), shipped with the
package as ``designer.spice.circuits``; see :mod:`designer.spice.library`."""
