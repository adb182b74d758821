"""Where the sun a zone's windows let in is absorbed (docs/model.md section 4.1), as EnergyPlus
distributes it (Engineering Reference, "Interior Solar Distribution" and "Interior Diffuse Solar";
HeatBalanceSurfaceManager.cc, ComputeIntSWAbsorpFactors; SolarShading.cc,
ComputeIntSolarAbsorpFactors).

Each function takes one entry per inside face of the zone: area A (m2), solar absorptance alpha
(-; a window's back-side absorptance of its panes) and transmittance tau_out (-; 0 for an opaque
face, a window's diffuse transmittance back out). Fractions are of the sun entering the zone (-).
"""
import numpy as np


def diffuse_fractions(area, absorptance, transmittance):
    """Fraction of the diffuse sun in a zone that each face absorbs,

        psi_i = A_i alpha_i / sum_j A_j (alpha_j + tau_out,j)

    every interreflection counted: what the faces reflect stays in the zone's diffuse pool until it
    is absorbed or leaves through a window, so the pool goes out in proportion to A (alpha + tau).
    What leaves is sum_j A_j tau_out,j / the same sum, 1 - sum_i psi_i; a zone without windows
    keeps all of it."""
    area, alpha, tau = (np.asarray(x, dtype=float) for x in (area, absorptance, transmittance))
    return area * alpha / np.sum(area * (alpha + tau))


def window_diffuse_fractions(area, absorptance, transmittance, view):
    """Fraction of the diffuse sun a window lets into a zone that each face absorbs, its first
    bounce by the window's view factors (EnergyPlus's CalcWinTransDifSolInitialDistribution):
    face i receives F_wi of it, absorbs alpha_i and reflects rho_i = 1 - alpha_i - tau_out,i
    (a window's tau_out of it leaves), and what all faces reflect joins the zone's diffuse pool
    (`diffuse_fractions`),

        psi_i = F_wi alpha_i + (sum_k F_wk rho_k) A_i alpha_i / sum_j A_j (alpha_j + tau_out,j)

    `view` (n,) is the window's row of the zone's view factors F_wk (-), 0 toward itself and the
    faces in its own plane, which it does not see: none of the first bounce leaves through the
    window itself or a window beside it. The row is scaled to sum to 1: EnergyPlus's fixed view
    factors are complete only to its fix's tolerance (`model.longwave.fix_view_factors`), and the
    sun a window lets in is then neither lost nor made."""
    alpha, tau, view = (np.asarray(x, dtype=float) for x in (absorptance, transmittance, view))
    view = view / np.sum(view)
    reflected = np.sum(view * (1.0 - alpha - tau))
    return view * alpha + reflected * diffuse_fractions(area, alpha, tau)


def beam_fractions(area, absorptance, transmittance, floor):
    """Fraction of the direct sun in a zone that each face absorbs where it all falls on the floor
    (EnergyPlus's MinimalShadowing and FullExterior solar distributions): the floors (the faces of
    the boolean mask `floor`) take it in proportion to their areas, each absorbing its alpha, and
    what they reflect joins the diffuse pool (`diffuse_fractions`),

        phi_i = [floor_i] A_i alpha_i / A_floor + rho_b psi_i,
        rho_b = 1 - sum over the floors of A_i alpha_i / A_floor."""
    area, alpha, tau = (np.asarray(x, dtype=float) for x in (area, absorptance, transmittance))
    floor = np.asarray(floor, dtype=bool)
    share = np.where(floor, area, 0.0) / np.sum(area[floor])
    absorbed = share * alpha
    return absorbed + (1.0 - np.sum(absorbed)) * diffuse_fractions(area, alpha, tau)
