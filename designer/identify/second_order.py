"""All second-order step methods (seeds 000, 002 and 003), in the order the step identification runs them.

:data:`STEP_METHODS` gathers three families, one module each:

- :mod:`.underdamped`: the methods that read an underdamped (or near-critical)
  response: overshoot, log-decrement, t4-t3, chen;
- :mod:`.overdamped`: the well-damped and overdamped ones, read from crossing
  times: two-pole, stark-mollenkamp, jahanmiri-fallahi, peeling,
  alfaro-123c-overdamped, harriott;
- :mod:`.dc_motor`: the DC motor's velocity (dc-motor) and position responses.

What they share (the signature ``method(t, y, yf, sigma=None) -> MethodResult``,
the normalised response, ``valid=False`` with a note instead of an exception)
is :mod:`._step_methods`.

Methods (``STEP_METHODS``, in this order):

========================  =======================================================
``overshoot``             first overshoot and peak time (seed 000 eqs 20-23,
                          seed 003 eq 2.2.11); no dead time
``log-decrement``         first and second overshoot and the period
                          (seed 002 eqs 5-7), zeta <= 0.5
``t4-t3``                 times to 26.4 % and 80.1 % (seed 002 eqs 8-12, Table 2
                          computed here from the exact response), 0.5 <= zeta <= 2
``two-pole``              two real poles from two points above 50 %
                          (seed 002 eqs 16-20), zeta > 2
``chen``                  Cheng-Liang Chen, underdamped with dead time
                          (seed 000 eqs 24-30)
``stark-mollenkamp``      three points 15/45/75 % (seed 000 eqs 31-37)
``jahanmiri-fallahi``     three points 2 or 5/70/90 % (seed 000 eqs 38-42)
``peeling``               exponential peeling of two time constants on a
                          semilog plot (seed 003 section 2.3)
``dc-motor``              DC motor velocity, Km = W(inf)/a,
                          tau_m = -t0 / ln(1 - w(t0)/W(inf)) (seed 000 eqs 52-55)
``alfaro-123c-overdamped`` Alfaro's 123c overdamped second order with dead time,
                          25/50/75 % points (the method of seed 000's Table II
                          "Alfaro" row, extended to two poles)
``harriott``              Harriott (1964): tau1 + tau2 from the 73 % time, their
                          ratio from the response at half that sum (his chart,
                          computed here from the exact response)
========================  =======================================================

:func:`~designer.identify.dc_motor.dc_motor_position` (an integrating, never-settling
response) is not in ``STEP_METHODS`` because the step orchestrator needs a settled final value.
"""

from __future__ import annotations

from .dc_motor import dc_motor
from .overdamped import alfaro_123c_overdamped, harriott, jahanmiri_fallahi, peeling, stark_mollenkamp, two_pole
from .underdamped import chen, log_decrement, overshoot, t4_t3

__all__ = ["STEP_METHODS"]


STEP_METHODS = [overshoot, log_decrement, t4_t3, two_pole, chen, stark_mollenkamp,
                jahanmiri_fallahi, peeling, dc_motor, alfaro_123c_overdamped, harriott]
