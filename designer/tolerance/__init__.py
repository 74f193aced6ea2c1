"""Tolerance analysis (issue 17): what fraction of real builds meets a spec.

A design's parts vary within their tolerances (:mod:`.parts`); samples of
them are drawn reproducibly, sample i a function of (seed, i) alone
(:mod:`.sampling`); an engine computes every figure of every sample at once
(:mod:`.plant`: the Sallen-Key plant, analytic, vectorised over the samples);
:mod:`.stats` turns the figures into statistics, a yield with its Wilson
interval, variance shares and the part to buy tighter. Imports go
front ends -> check -> tolerance -> wings.
"""
