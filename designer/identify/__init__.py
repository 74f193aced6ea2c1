"""Classical identification from step and frequency responses (seeds 000, 002, 003).

``io`` reads scope captures and Bode tables; ``preprocess`` turns a capture
into a normalised step, by stages: ``edges`` (the record checked, its steps
found), ``settle`` (baseline, final value), ``normalise`` (one step) and
``averaging`` (a square wave's steps); ``first_order``, the second-order
families ``underdamped``, ``overdamped`` and ``dc_motor`` (listed in
``second_order``) and ``refine`` (least squares) are the step methods on the
shared ``structures``;
``step`` runs and ranks them, ``frequency`` does the same for a Bode table
(the model responses and classical readings of ``bode_readings``, the
least-squares fit of ``freqfit``, the loop margins of ``bode_margins``);
``correlation`` and ``spectral`` estimate the impulse and frequency
responses from a broadband input (a PRBS, :mod:`designer.core.prbs`, or
noise: seed 003, 2.4 and 3.2) and ``broadband`` recognises such an input and
runs both, with the step and frequency methods on their results;
``outputerror`` fits continuous-time models with dead time to any recorded
input by output error, and ``validation`` judges a model on data it was not
fitted to (fit percentage, residual tests, an ARX reference);
``against`` compares an identified plant with its design (the one use of the
plant wing) and ``report`` prints and plots the results. The waveform
readings they share (noise, crossings, derivative, tangent) are
:mod:`designer.core.waveform`.
"""
