"""The heat loss coefficient of a model (docs/model.md section 8).

The HLC is the steady-state heat loss per kelvin of indoor-outdoor difference: no sun, every
prescribed temperature (outdoor air, sky, boundary columns, supply air) at 0 C, the air of every
zone held at 1 C; the heat that must then be given to the zones' air is the HLC (W/K). It is the
number an in-situ test is run for (IEA EBC Annex 71), and, unlike how a loss splits among
effects, one that a record of the indoor air and the heating power fixes well.

The steady state is that of the network's conductances alone: with the inputs u and the constant
sources q at zero, the free nodes (walls, radiant nodes, any node an effect adds) satisfy
A_ff T_f = -A_fa T_a with T_a = 1, and the heat to the air is -(A T)_a summed over the zones.
"""
import numpy as np
from scipy import sparse
from scipy.sparse.linalg import spsolve

from .network import assemble


def heat_loss_coefficient(building, network=None):
    """Heat loss coefficient (W/K) of a `Building`.

    Parameters
    ----------
    building : Building
    network : Network, optional
        The building's assembled network, if already at hand (only its conductance matrix A is
        used, so any input order will do).

    Returns
    -------
    float
        W/K: the heat given to the zones' air, every zone's air at 1 C and every prescribed
        temperature at 0 C, in steady state.
    """
    A = sparse.csr_matrix((assemble(building) if network is None else network).A)
    air = np.array([z.air_node - 1 for z in building.zones])
    free = np.setdiff1d(np.arange(A.shape[0]), air)
    T = np.zeros(A.shape[0])
    T[air] = 1.0
    if free.size:
        A_ff = A[free][:, free].tocsc()
        T[free] = spsolve(A_ff, -(A[free][:, air] @ T[air]))
    return float(-(A[air] @ T).sum())
