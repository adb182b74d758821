"""Long-wave exchange between a zone's inside faces as EnergyPlus computes it (docs/model.md
section 3.5): approximate view factors from the faces' areas and orientations, their fix for
reciprocity and completeness, and Hottel's ScriptF, the grey exchange factors of the enclosure
(EnergyPlus's HeatBalanceIntRadExchange: `CalcApproximateViewFactors`, `FixViewFactors`,
`CalcScriptF`; Engineering Reference, "Interior Long-Wave Radiation Exchange"). Areas in m2,
angles in degrees, view and exchange factors dimensionless, conductances in W/K.
"""
import numpy as np

SIGMA = 5.670374419e-8  # W/m2/K4, Stefan-Boltzmann
# The mean temperature the exchange is linearised at (K): 4 sigma T_m^3 = 5.71 W/m2/K at 20 C,
# a room's usual surface temperature, as the converter's h_rad of a star node takes it
T_MEAN = 293.15
# Faces whose azimuths and tilts are both within this of each other face the same way and do not
# see each other (deg; EnergyPlus's SameAngleLimit)
SAME_ANGLE = 10.0
# EnergyPlus limits an emissivity below 1 to keep (1 - eps) from dividing by zero
MAX_EMISSIVITY = 0.99999
# FixViewFactors' convergence of |sum F - N|: reached, or changing by less than the second
PRIMARY_CONVERGENCE, DIFFERENCE_CONVERGENCE, MAX_ITERATIONS = 0.001, 0.00001, 400


def face_class(tilt):
    """A face's class for its view factors where the file gives none (EnergyPlus's surface classes
    that matter to them, "floor", "roof", "internal_mass", and "wall" for every other face), from
    the tilt of its outward normal, away from the room (deg): within 45 deg of looking down a
    floor, of up a roof."""
    return "floor" if tilt > 135.0 else "roof" if tilt < 45.0 else "wall"


def approximate_view_factors(areas, tilts, azimuths, classes):
    """F (n, n), F[i, j] the part of face i's view that is face j, as EnergyPlus approximates it:
    F_ij = A_j / sum of the areas face i sees, where i sees j unless they face the same way
    (azimuths and tilts within `SAME_ANGLE`), except that every face sees a floor, a roof and an
    internal mass, and no face itself. As in EnergyPlus, a roof counts in the area a face sees
    only from a floor: `fix_view_factors` restores completeness."""
    A = np.asarray(areas, dtype=float)
    tilts, azimuths = np.asarray(tilts, dtype=float), np.asarray(azimuths, dtype=float)
    classes = np.asarray(classes)
    apart = ((np.abs(azimuths[:, None] - azimuths[None, :]) > SAME_ANGLE)
             | (np.abs(tilts[:, None] - tilts[None, :]) > SAME_ANGLE))
    always = np.isin(classes, ("floor", "internal_mass"))[None, :]
    roof = (classes == "roof")[None, :]
    off = ~np.eye(len(A), dtype=bool)
    counted = off & (always | (roof & (classes == "floor")[:, None]) | apart)
    seen = off & (always | roof | apart)
    total = counted.astype(float) @ A
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(seen & (total[:, None] > 0.0), A[None, :] / total[:, None], 0.0)


def fix_view_factors(areas, F):
    """EnergyPlus's fix of view factors F (n, n) for reciprocity, A_i F_ij = A_j F_ji, and
    completeness, sum_j F_ij = 1: a face larger than all the others together sees itself by
    min(0.9, 1.2 A_i / sum A); then the row of A_i F_ij is scaled to sum to A_i and A F averaged
    with its transpose, until |sum F - n| is below 0.001 or changes by less than 1e-5 (at most
    400 times). Three faces or fewer get reciprocity alone, scaled so that no row exceeds 1. The
    fixed F is taken where it is more complete than F, as EnergyPlus takes it."""
    A = np.asarray(areas, dtype=float)
    F = np.asarray(F, dtype=float)
    n = len(A)
    original = abs(F.sum() - n)
    AF = F.copy()
    largest = int(np.argmax(A))
    if A[largest] > A.sum() - A[largest]:
        AF[largest, largest] = min(0.9, 1.2 * A[largest] / A.sum())
    AF = AF * A[:, None]
    AF = 0.5 * (AF + AF.T)
    if n <= 3:
        fixed = AF / A[:, None]
        if fixed.sum() > n + 0.01:
            fixed = fixed / fixed.sum(axis=1).max()
        return fixed
    old = 10.0
    for _ in range(MAX_ITERATIONS):
        rows = AF.sum(axis=1)
        AF = AF * np.where(np.abs(rows) > 1e-10, A / np.where(rows == 0.0, 1.0, rows), 1.0)[:, None]
        AF = 0.5 * (AF + AF.T)
        fixed = AF / A[:, None]
        small = np.abs(fixed) < 1e-10
        fixed[small], AF[small] = 0.0, 0.0
        new = abs(fixed.sum() - n)
        if abs(old - new) < DIFFERENCE_CONVERGENCE or new <= PRIMARY_CONVERGENCE:
            break
        old = new
    return fixed if new < original or new < PRIMARY_CONVERGENCE else F


def script_f(areas, F, emissivities):
    """Hottel's ScriptF (n, n): the part of face j's black-body emission sigma T_j^4 that face i
    absorbs, per m2 of face i, in the grey enclosure of view factors F and emissivities eps
    (`MAX_EMISSIVITY` at most). The radiosities J of the faces when face j alone emits solve
    A_i J_i / (1 - eps_i) - A_i sum_k F_ik J_k = A_i eps_i E_i / (1 - eps_i), E_i = delta_ij;
    face i absorbs eps_i (J_i - eps_i E_i) / (1 - eps_i) less what it emits (EnergyPlus's
    CalcScriptF). Reciprocal: A_i ScriptF_ij = A_j ScriptF_ji where A F is."""
    A = np.asarray(areas, dtype=float)
    eps = np.minimum(np.asarray(emissivities, dtype=float), MAX_EMISSIVITY)
    factor = A / (1.0 - eps)
    M = A[:, None] * np.asarray(F, dtype=float) - np.diag(factor)
    J = np.linalg.solve(M, np.diag(-eps * factor))
    return (eps / (1.0 - eps))[:, None] * (J - np.diag(eps))


def exchange_conductances(areas, SF, T_mean=T_MEAN):
    """G (n, n) W/K: the linearised exchange A_i ScriptF_ij 4 sigma T_m^3 between each pair of
    faces (sigma (T_i^4 - T_j^4) ~ 4 sigma T_m^3 (T_i - T_j)), averaged with its transpose for an
    exactly symmetric network; the diagonal (a face's exchange with itself) is zero."""
    G = np.asarray(areas, dtype=float)[:, None] * SF * 4.0 * SIGMA * T_mean ** 3
    G = 0.5 * (G + G.T)
    np.fill_diagonal(G, 0.0)
    return G


def absorbed_shares(areas, emissivities):
    """The part of a zone's radiant gains each face absorbs, A_i eps_i / sum_k A_k eps_k
    (EnergyPlus spreads them by area times thermal absorptance)."""
    weights = np.asarray(areas, dtype=float) * np.asarray(emissivities, dtype=float)
    return weights / weights.sum()


def declared_view_factors(names, declared):
    """F (n, n) of the faces `names` from declared (from, to, F) triples (a zone's
    `view_factors`); pairs not declared are 0."""
    index = {name: k for k, name in enumerate(names)}
    F = np.zeros((len(names), len(names)))
    for a, b, value in declared:
        F[index[a], index[b]] = value
    return F


def enclosure_exchange(names, areas, emissivities, tilts, azimuths, classes, declared=()):
    """(G, shares) of a zone's faces: the conductances of their linearised ScriptF exchange (W/K,
    `exchange_conductances`) and the part of the radiant gains each absorbs (`absorbed_shares`).
    The view factors are the declared ones where given, else approximated, both fixed for
    reciprocity and completeness as EnergyPlus fixes them; a face without a class takes it from
    its tilt (`face_class`)."""
    classes = [face_class(t) if c is None else c for c, t in zip(classes, tilts)]
    F = (declared_view_factors(names, declared) if declared
         else approximate_view_factors(areas, tilts, azimuths, classes))
    F = fix_view_factors(areas, F)
    return (exchange_conductances(areas, script_f(areas, F, emissivities)),
            absorbed_shares(areas, emissivities))


def pair_coefficient(T_a, T_b):
    """sigma (T_a^4 - T_b^4) / (T_a - T_b) = sigma (T_a^2 + T_b^2)(T_a + T_b) (W/m2/K, T_a and T_b
    in C, taken in K): times A_a ScriptF_ab the conductance of two faces' exchange at their own
    temperatures, as EnergyPlus computes it each step (HeatBalanceIntRadExchange.cc,
    CalcInteriorRadExchange); 4 sigma T^3 where they meet, `exchange_conductances`'s at T_MEAN."""
    return exterior_coefficient(1.0, T_a, T_b)


def exterior_coefficient(emissivity, T_face, T_other):
    """An outside face's long-wave coefficient (W/m2/K) toward the sky, the air or the ground at
    T_other (C) from its own temperature T_face (C), as EnergyPlus computes it each step
    (Engineering Reference, "External Longwave Radiation"): h = eps sigma (T_s^4 - T^4) / (T_s - T)
    in K, written as eps sigma (T_s^2 + T^2)(T_s + T), which is the same where T_s != T and its
    limit, 4 eps sigma T^3, where they meet. The view factor it is exchanged through multiplies it
    elsewhere."""
    T_s, T = np.asarray(T_face, dtype=float) + 273.15, np.asarray(T_other, dtype=float) + 273.15
    return emissivity * SIGMA * (T_s * T_s + T * T) * (T_s + T)
