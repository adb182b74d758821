"""Spatial discretisation of a multilayer component (docs/model.md section 2), per m2 of area.

Conductances are exact integrals of dx/lambda across layer boundaries, capacities exact
integrals of rho*c over each node's control volume: with two nodes this is the R2C model
of the paper (K = 1/R and two half capacities).
"""
import math
from itertools import accumulate

import numpy as np


def layer_bounds(thicknesses):
    """Depths (m) of the layer interfaces, from 0 to the total thickness."""
    return np.concatenate(([0.0], np.cumsum(thicknesses)))


def _integrals(bounds, density, a, b):
    """Integrals over each [a_k, b_k] (m) of a piecewise-constant profile `density` given per layer."""
    a, b = np.asarray(a, dtype=float)[:, None], np.asarray(b, dtype=float)[:, None]
    lo = np.clip(bounds[None, :-1], a, b)
    hi = np.clip(bounds[None, 1:], a, b)
    return np.sum(density * (hi - lo), axis=1)


def conductances(layers, depths):
    """Conductances G_k (W/m2/K) between successive nodes.

    Parameters
    ----------
    layers : sequence of (Material, thickness m), inside face first
    depths : node depths x_0 = 0 < ... < x_m = L (m)

    Returns
    -------
    ndarray of m values, G_k = 1 / integral(dx / lambda, x_k, x_k+1)
    """
    bounds = layer_bounds([t for _, t in layers])
    resistivity = np.array([1.0 / m.conductivity for m, _ in layers])
    x = np.asarray(depths, dtype=float)
    return 1.0 / _integrals(bounds, resistivity, x[:-1], x[1:])


def capacities(layers, depths):
    """Heat capacities C_k (J/m2/K) of the nodes, over [(x_k-1 + x_k)/2, (x_k + x_k+1)/2]
    clipped to [0, L]: end nodes get half cells."""
    bounds = layer_bounds([t for _, t in layers])
    rho_c = np.array([m.density * m.specific_heat for m, _ in layers])
    x = np.asarray(depths, dtype=float)
    mid = (x[:-1] + x[1:]) / 2
    lo = np.concatenate(([x[0]], mid))
    hi = np.concatenate((mid, [x[-1]]))
    return _integrals(bounds, rho_c, lo, hi)


def generated_depths(thicknesses, max_spacing, layer_boundaries=True, extra=(), merge=1e-3):
    """Node depths (m) from the inside face: both surfaces, every layer boundary (unless
    `layer_boundaries` is false) and the `extra` depths (sensors), with each stretch between them
    cut into equal cells no thicker than `max_spacing` (m). An extra depth within `merge` (m) of a
    surface or layer boundary is that node: a sensor "at" an interface is placed to the millimetre."""
    total = float(sum(thicknesses))
    fixed = [0.0, total] + (list(accumulate(thicknesses))[:-1] if layer_boundaries else [])
    fixed += [float(x) for x in extra if min(abs(x - f) for f in fixed) > merge]
    fixed = sorted(set(fixed))
    depths = [fixed[0]]
    for a, b in zip(fixed, fixed[1:]):
        cells = max(1, math.ceil((b - a) / max_spacing - 1e-9))
        depths += [a + (b - a) * k / cells for k in range(1, cells + 1)]
    return depths
