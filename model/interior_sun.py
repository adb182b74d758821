"""Where the sun a zone's windows let in is absorbed (docs/model.md section 4.1), as EnergyPlus
distributes it (Engineering Reference, "Interior Solar Distribution" and "Interior Diffuse Solar";
HeatBalanceSurfaceManager.cc, ComputeIntSWAbsorpFactors; SolarShading.cc,
ComputeIntSolarAbsorpFactors).

Each function takes one entry per inside face of the zone: area A (m2), solar absorptance alpha
(-; a window's back-side absorptance of its panes) and transmittance tau_out (-; 0 for an opaque
face, a window's diffuse transmittance back out). Fractions are of the sun entering the zone (-).
`model.beam_trace` traces the direct sun through a window onto the zone's faces (EnergyPlus's
FullInteriorAndExterior distribution); these are plain arrays, what an FMU computes with.
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
    the boolean mask `floor`) take it in proportion to their areas, each absorbing its alpha, a
    window's tau_out of it leaving, and what they reflect joins the diffuse pool
    (`diffuse_fractions`),

        phi_i = [floor_i] A_i alpha_i / A_floor + rho_b psi_i,
        rho_b = 1 - sum over the floors of A_i (alpha_i + tau_out,i) / A_floor.

    With one face as the mask, the split of the direct sun that falls on that face
    (`model.beam_trace.beam_shares`)."""
    area, alpha, tau = (np.asarray(x, dtype=float) for x in (area, absorptance, transmittance))
    floor = np.asarray(floor, dtype=bool)
    share = np.where(floor, area, 0.0) / np.sum(area[floor])
    absorbed = share * alpha
    return absorbed + (1.0 - np.sum(share * (alpha + tau))) * diffuse_fractions(area, alpha, tau)


def with_absorber(split, area, absorptance, transmittance, absorbing_area):
    """A zone's split of the sun (`beam_fractions`, `window_diffuse_fractions`, a traced face's
    or a declared one) once a face the sun reaches only through the diffuse pool joins the
    zone, as an internal mass does (EnergyPlus traces no beam onto an InternalMass):

        phi_i' = phi_i - R psi_i a / (S + a),   phi_mass = R a / (S + a),

    a = A alpha of the new face (m2), S = sum_j A_j (alpha_j + tau_out,j) (m2), psi the zone's
    `diffuse_fractions` and R the part of the split's sun that joins the pool. phi_i = first_i +
    R psi_i, first_i >= 0 its first bounce; a face in the plane of the window the sun came
    through (its own wall, the window itself) takes none of the first bounce, nor does every
    face but the one the beam falls on, so R = min over the faces of phi_i / psi_i, exact
    wherever one such face has psi_i > 0; a split that puts all its sun on one face (R = 0)
    gives the new face none. What leaves through the windows falls with the pool's share of the
    rest: the split still adds up to what the zone keeps.

    split, area, absorptance, transmittance: (n,) the zone's faces' shares (-), areas (m2),
    absorptances and diffuse transmittances back out (-); absorbing_area: a (m2).
    Returns (phi' (n,), phi_mass)."""
    split, area, alpha, tau = (np.asarray(x, dtype=float) for x in (split, area, absorptance, transmittance))
    psi = diffuse_fractions(area, alpha, tau)
    pooled = psi > 0
    R = float(np.clip(np.min(split[pooled] / psi[pooled]), 0.0, 1.0)) if pooled.any() else 0.0
    taken = absorbing_area / (np.sum(area * (alpha + tau)) + absorbing_area)
    return split - R * psi * taken, R * taken
