"""Assemble the nodal network `C dT/dt = A T + B u(t) + q` (PHYSICS.md section 3, paper eq. 5).

Node i of the building file is row i-1. The input vector u holds, in this order: `T_out`,
`T_sky` (C), `I_<component>` for each exterior component (W/m2 on its outside face), then the
building's named input columns (heat inputs W, boundary temperatures C). Constant sources
(internal gains, fixed boundary temperatures) go to q (W) rather than to a constant input,
so that u holds only what varies in time.
"""
from dataclasses import dataclass

import numpy as np

from .discretise import capacities, conductances

RHO_C_AIR = 1.2 * 1005.0  # J/m3/K


@dataclass(frozen=True)
class Network:
    C: np.ndarray  # (N,) J/K, 0 on algebraic (radiant) nodes
    A: np.ndarray  # (N, N) W/K
    B: np.ndarray  # (N, n_inputs)
    q: np.ndarray  # (N,) W
    input_names: tuple  # names of the columns of B

    @property
    def n_nodes(self):
        return len(self.C)

    @property
    def algebraic(self):
        """Boolean mask of the nodes with no capacity (radiant nodes)."""
        return self.C == 0.0


def input_names(building):
    """The input vector's names, in the order of the columns of B."""
    return (("T_out", "T_sky") + tuple(f"I_{c.name}" for c in building.exterior_components)
            + building.input_columns)


def sky_view_factor(tilt):
    """F = (1 + cos(tilt)) / 2 for a tilt in degrees from horizontal (1 for a roof, 0.5 for a wall)."""
    return (1.0 + np.cos(np.radians(tilt))) / 2.0


def assemble(building):
    """Build the `Network` of a validated `Building`."""
    n = building.n_nodes
    names = input_names(building)
    col = {name: j for j, name in enumerate(names)}
    C = np.zeros(n)
    A = np.zeros((n, n))
    B = np.zeros((n, len(names)))
    q = np.zeros(n)

    def link(i, j, g):
        """A conductance g (W/K) between nodes i and j (0-based)."""
        A[i, i] -= g
        A[j, j] -= g
        A[i, j] += g
        A[j, i] += g

    def to_zone(node, zone_name, area, h_conv, h_rad):
        zone = building.zone(zone_name)
        link(node, zone.air_node - 1, area * h_conv * zone.convection_factor)
        link(node, zone.radiant_node - 1, area * h_rad)

    for c in building.components:
        idx = [i - 1 for i in c.node_ids]
        C[idx] += c.area * capacities(c.layers, c.depths)
        for k, g in enumerate(conductances(c.layers, c.depths)):
            link(idx[k], idx[k + 1], c.area * g * c.conductivity_factor)
        to_zone(idx[0], c.inside["zone"], c.area, c.inside["h_conv"], c.inside["h_rad"])
        e, out = idx[-1], c.outside
        if out["type"] == "exterior":
            F = sky_view_factor(c.tilt)
            A[e, e] -= c.area * (out["h_conv"] + out["h_rad"])
            B[e, col["T_out"]] += c.area * (out["h_conv"] + out["h_rad"] * (1.0 - F))
            B[e, col["T_sky"]] += c.area * out["h_rad"] * F
            B[e, col[f"I_{c.name}"]] += c.area * out["solar_absorptance"]
        elif out["type"] == "zone":
            to_zone(e, out["zone"], c.area, out["h_conv"], out["h_rad"])
        elif out["type"] == "boundary":
            g = c.area * out["h"]
            A[e, e] -= g
            if isinstance(out["temperature"], str):
                B[e, col[out["temperature"]]] += g
            else:
                q[e] += g * out["temperature"]
        if c.solar_transmittance is not None:
            receiver = building.component(c.transmitted_solar_to)
            B[receiver.node_ids[0] - 1, col[f"I_{c.name}"]] += c.solar_transmittance * c.area

    for z in building.zones:
        air = z.air_node - 1
        C[air] += RHO_C_AIR * z.volume
        g_vent = RHO_C_AIR * z.volume * z.air_change_rate / 3600.0
        A[air, air] -= g_vent
        B[air, col["T_out"]] += g_vent
        q[air] += z.internal_gain
        if z.heat_input:
            B[air, col[z.heat_input]] += 1.0
    return Network(C=C, A=A, B=B, q=q, input_names=names)
