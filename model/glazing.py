"""Glazing physics (docs/model.md section 4.1): a pane's and a stack of panes' solar
transmittance with the angle of incidence, its hemispherical (diffuse) mean, the conductance of a
gas gap, and the solar transmittance EnergyPlus's simple glazing model gives a (U, SHGC) pair and
its change with the angle of incidence.

Angles in degrees, conductances in W/m2/K, transmittances and reflectances dimensionless.
"""
import numpy as np

from .longwave import SIGMA

# Angles (deg) at which a glazing's transmittance is tabulated in a building file
ANGLES = tuple(range(0, 91, 10))


def pane_optics(T0, R0):
    """(r, tau) of an uncoated pane from its solar transmittance T0 and reflectance R0 at normal
    incidence: r the reflectance of one air-glass interface, tau the internal transmittance of the
    glass, from T0 = (1 - r)^2 tau / (1 - r^2 tau^2) and R0 = r + r (1 - r)^2 tau^2 / (1 - r^2 tau^2)
    (the pane's interreflections summed)."""
    if not (0 < T0 < 1 and 0 <= R0 < 1 and T0 + R0 <= 1):
        raise ValueError(f"a pane needs 0 < T < 1, 0 <= R < 1 and T + R <= 1 (T={T0}, R={R0})")

    def tau_of(r):
        if r == 0:
            return T0
        return (-(1 - r) ** 2 + np.sqrt((1 - r) ** 4 + 4 * T0 ** 2 * r ** 2)) / (2 * T0 * r ** 2)

    def reflectance(r):
        tau = tau_of(r)
        return r + r * (1 - r) ** 2 * tau ** 2 / (1 - r ** 2 * tau ** 2) - R0

    if R0 <= 1e-9:
        return 0.0, T0
    # imported here: the FMU imports this module for its gaps, and scipy's extension modules,
    # once loaded in an FMU's embedded Python, read freed memory as a C host unloads it
    # (tests/test_fmu_memory.py); only the converter needs the root
    from scipy.optimize import brentq
    r = brentq(reflectance, 1e-12, R0)
    return r, tau_of(r)


def pane_from_refraction(thickness, n, K):
    """(T0, R0), the solar transmittance and reflectance at normal incidence of an uncoated pane of
    thickness (m), index of refraction n and extinction coefficient K (1/m), as EnergyPlus reads a
    WindowMaterial:Glazing:RefractionExtinctionMethod: one interface reflects r = ((n - 1)/(n + 1))^2,
    the glass transmits tau = exp(-K thickness), and the pane's interreflections sum as in
    `pane_optics` (whose inverse this is)."""
    r = ((n - 1) / (n + 1)) ** 2
    tau = np.exp(-K * thickness)
    d = 1 - (r * tau) ** 2
    return (1 - r) ** 2 * tau / d, r * (1 + (1 - r) ** 2 * tau ** 2 / d)


def pane_at(T0, R0, angle):
    """(T, R) of an uncoated pane at an angle of incidence (deg, 0 normal): Fresnel's interface
    reflectances for s and p light at the refractive index r gives, the glass's absorption over the
    refracted path (tau^(1 / cos theta')), the pane's interreflections, s and p averaged."""
    r0, tau0 = pane_optics(T0, R0)
    phi = np.radians(np.asarray(angle, dtype=float))
    n = (1 + np.sqrt(r0)) / (1 - np.sqrt(r0))
    phi_t = np.arcsin(np.sin(phi) / n)
    tau = tau0 ** (1.0 / np.cos(phi_t))
    with np.errstate(invalid="ignore", divide="ignore"):
        rs = np.where(phi > 1e-9, (np.sin(phi - phi_t) / np.sin(phi + phi_t)) ** 2, r0)
        rp = np.where(phi > 1e-9, (np.tan(phi - phi_t) / np.tan(phi + phi_t)) ** 2, r0)
    rs, rp = np.where(phi >= np.pi / 2 - 1e-9, 1.0, rs), np.where(phi >= np.pi / 2 - 1e-9, 1.0, rp)
    T = R = 0.0
    for r in (rs, rp):
        d = 1 - r ** 2 * tau ** 2
        T = T + 0.5 * (1 - r) ** 2 * tau / d
        R = R + 0.5 * (r + r * (1 - r) ** 2 * tau ** 2 / d)
    return T, R


def stack_transmittance(panes, angle):
    """Solar transmittance of panes in series (outside first), each (T0, R0) at normal incidence
    and the same on both faces, at an angle of incidence (deg): adding a pane behind a stack of
    transmittance T, back reflectance R_b gives T T_k / (1 - R_b R_k) (interreflections between
    them), R_b' = R_k + T_k^2 R_b / (1 - R_b R_k)."""
    T, Rb = None, None
    for T0, R0 in panes:
        Tk, Rk = pane_at(T0, R0, angle)
        if T is None:
            T, Rb = Tk, Rk
        else:
            d = 1 - Rb * Rk  # 0 only at grazing incidence, where every pane reflects all
            safe = np.where(d > 0, d, 1.0)
            T, Rb = np.where(d > 0, T * Tk / safe, 0.0), np.where(d > 0, Rk + Tk ** 2 * Rb / safe, 1.0)
    return T


def stack_reflectance(panes):
    """Front solar reflectance of panes in series (outside first) at normal incidence."""
    R = T = None
    for T0, R0 in panes:
        if R is None:
            T, R, Rb = T0, R0, R0
        else:
            d = 1 - Rb * R0
            R, T, Rb = R + T ** 2 * R0 / d, T * T0 / d, R0 + T0 ** 2 * Rb / d
    return R


def hemispherical(transmittance, n=91):
    """The diffuse (hemispherical) mean of an angular transmittance function f(angle deg),
    2 integral_0^(pi/2) f(theta) cos theta sin theta d theta, by the trapezoid rule on n angles;
    of several functions at once where f returns (k, n) values: their k means."""
    theta = np.linspace(0.0, np.pi / 2, n)
    mean = np.trapezoid(2 * np.asarray(transmittance(np.degrees(theta))) * np.cos(theta) * np.sin(theta), theta)
    return float(mean) if np.ndim(mean) == 0 else mean


def radiative_conductance(emissivity_1, emissivity_2, T_mean=283.15):
    """h_r = 4 sigma T_m^3 / (1/e1 + 1/e2 - 1) (W/m2/K): the linearised long-wave exchange between
    two parallel grey planes at a mean temperature T_m (K)."""
    return 4 * SIGMA * T_mean ** 3 / (1 / emissivity_1 + 1 / emissivity_2 - 1)


# The conductivity of air (W/m/K) at a temperature T (K), ISO 15099 / EnergyPlus's coefficients,
# and what the gap's convection is evaluated at: the mean temperature and the difference across it
AIR_CONDUCTIVITY = (2.873e-3, 7.76e-5)
GAP_T_MEAN = 283.15  # K
GAP_DELTA_T = 15.0  # K


# EnergyPlus's fill gases (its Material module's table, the IDD's defaults, ISO 15099): the
# coefficients (a, b, c) of conductivity (W/m/K), viscosity (kg/m/s) and specific heat (J/kg/K),
# each a + b T + c T^2 at T in K, and the molecular weight (g/mol)
GASES = {
    "air": ((2.873e-3, 7.760e-5, 0.0), (3.723e-6, 4.940e-8, 0.0), (1002.737, 1.2324e-2, 0.0), 28.97),
    "argon": ((2.285e-3, 5.149e-5, 0.0), (3.379e-6, 6.451e-8, 0.0), (521.929, 0.0, 0.0), 39.948),
    "krypton": ((9.443e-4, 2.826e-5, 0.0), (2.213e-6, 7.777e-8, 0.0), (248.091, 0.0, 0.0), 83.8),
    "xenon": ((4.538e-4, 1.723e-5, 0.0), (1.069e-6, 7.414e-8, 0.0), (158.340, 0.0, 0.0), 131.3),
}


def solar_spectrum():
    """(wavelengths um, irradiance W/m2/um) of the solar spectrum EnergyPlus and WINDOW weigh pane
    data with: ASTM E891-87 Table 1, direct normal at AM1.5 (ISO 9845-1), as LBNL's pywincalc ships it."""
    import os

    import pywincalc
    path = os.path.join(pywincalc.standard_path, "ASTM E891 Table 1 Direct AM1_5.ssp")
    rows = [line.split() for line in open(path)]
    table = np.array([[float(a), float(b)] for a, b, *_ in (r for r in rows if len(r) >= 2 and r[0][0].isdigit())])
    return table[:, 0], table[:, 1]


_trapezoid = getattr(np, "trapezoid", None) or np.trapz  # numpy 2 renamed it


def solar_average(wavelengths, values):
    """A spectral property (at `wavelengths` um) averaged over the solar spectrum: the integral of
    value x irradiance over that of irradiance, both by the trapezoid rule on the spectrum's
    wavelengths within the data's range (the value interpolated linearly)."""
    lam, E = solar_spectrum()
    inside = (lam >= np.min(wavelengths)) & (lam <= np.max(wavelengths))
    lam, E = lam[inside], E[inside]
    order = np.argsort(wavelengths)
    v = np.interp(lam, np.asarray(wavelengths)[order], np.asarray(values)[order])
    return float(_trapezoid(v * E, lam) / _trapezoid(E, lam))


def gas_properties(gas, T):
    """(conductivity W/m/K, viscosity kg/m/s, specific heat J/kg/K, molecular weight g/mol) at T (K)
    of a gas: a name of `GASES`, a tuple of its own coefficients as GASES holds them, or a mixture
    [(gas, mole fraction), ...], whose properties are the mole-fraction-weighted means (EnergyPlus
    mixes by ISO 15099's rules; for argon or krypton in air the two differ by a few per cent in k)."""
    if isinstance(gas, list):
        parts = [(gas_properties(g, T), x) for g, x in gas]
        total = sum(x for _, x in parts)
        return tuple(sum(p[i] * x for p, x in parts) / total for i in range(4))
    k, mu, cp, M = GASES[gas] if isinstance(gas, str) else gas
    value = lambda c: c[0] + c[1] * T + c[2] * T * T  # noqa: E731
    return value(k), value(mu), value(cp), M


def gap_convection(thickness, height, T_mean=GAP_T_MEAN, delta_T=GAP_DELTA_T, gas="air"):
    """Conduction and convection (W/m2/K) across a gas gap (`gas` as `gas_properties` reads it) of
    `thickness` m between two panes `height` m high, Nu k / d: ISO 15099's Nusselt number of a
    vertical cavity, the larger of its Nu_1(Ra) and Nu_2 = 0.242 (Ra / (H / d))^0.272, at the
    Rayleigh number Ra = rho^2 d^3 g c_p dT / (mu k T_m) of a mean temperature T_mean (K) and a
    difference delta_T (K) across the gap, the gas's properties at T_mean and its density at
    101325 Pa (EnergyPlus's WindowManager.cc, NusseltNumber). Arrays of gaps alike."""
    k, mu, cp, M = gas_properties(gas, T_mean)  # W/m/K, Pa s, J/kg/K, g/mol
    rho = 101325 * M / 1000 / (8.314462 * T_mean)  # kg/m3
    ra = rho ** 2 * thickness ** 3 * 9.81 * cp * np.abs(delta_T) / (mu * k * T_mean)
    aspect = height / thickness
    nu1 = np.where(ra > 5e4, 0.0673838 * ra ** (1 / 3),
                   np.where(ra > 1e4, 0.028154 * ra ** 0.4134, 1 + 1.7596678e-10 * ra ** 2.2984755))
    nu2 = 0.242 * (ra / aspect) ** 0.272
    return np.maximum(nu1, nu2) * k / thickness


def gap_conductance(thickness, height, emissivity_1, emissivity_2, T_mean=GAP_T_MEAN, delta_T=GAP_DELTA_T,
                    gas="air"):
    """Conductance (W/m2/K) of a gas gap: `gap_convection` plus the radiative exchange of its two
    faces linearised at T_mean (`radiative_conductance`)."""
    return float(gap_convection(thickness, height, T_mean, delta_T, gas)
                 + radiative_conductance(emissivity_1, emissivity_2, T_mean))


def gap_coefficients(gas):
    """A gas as `gas_properties` reads it, as the ten numbers a network holds: the coefficients
    (a, b, c) of its conductivity, viscosity and specific heat, then its molecular weight; a
    mixture's are the mole-fraction-weighted means of its gases' (its properties then the
    weighted means `gas_properties` gives)."""
    if isinstance(gas, list):
        total = sum(x for _, x in gas)
        return tuple(sum(gap_coefficients(g)[i] * x for g, x in gas) / total for i in range(10))
    k, mu, cp, M = GASES[gas] if isinstance(gas, str) else gas
    return (*k, *mu, *cp, M)


def followed_gap_conductance(T_1, T_2, thickness, height, emissivity, coefficients):
    """Conductance (W/m2/K) of gas gaps between panes at T_1 and T_2 (C), as EnergyPlus solves its
    panes (WindowManager.cc, SolveForWindowTemperatures): `gap_convection` at their mean and
    difference, plus the exact long-wave exchange eps sigma (T_1^4 - T_2^4) / (T_1 - T_2) =
    eps sigma (T_1^2 + T_2^2)(T_1 + T_2) (K) of two grey planes, eps = 1 / (1/e_1 + 1/e_2 - 1);
    `coefficients` (n, 10) as `gap_coefficients` gives them."""
    t1, t2 = np.asarray(T_1, dtype=float) + 273.15, np.asarray(T_2, dtype=float) + 273.15
    c = np.asarray(coefficients, dtype=float).T
    gas = ((c[0], c[1], c[2]), (c[3], c[4], c[5]), (c[6], c[7], c[8]), c[9])
    convective = gap_convection(thickness, height, 0.5 * (t1 + t2), t1 - t2, gas)
    return convective + emissivity * SIGMA * (t1 * t1 + t2 * t2) * (t1 + t2)


def simple_glazing_transmittance(U, shgc):
    """Solar transmittance at normal incidence of EnergyPlus's simple glazing system from its
    U-factor (W/m2/K) and SHGC (Engineering Reference, "Simple Window Model", step 3): the
    correlations for U >= 4.5 and U <= 3.4, linearly interpolated between."""
    def low(s):
        return 0.085775 * s ** 2 + 0.963954 * s - 0.084958 if s > 0.15 else 0.4104 * s

    def high(s):
        return 0.939998 * s ** 2 + 0.20332 * s

    if U >= 4.5:
        return high(shgc)
    if U <= 3.4:
        return low(shgc)
    w = (U - 3.4) / 1.1
    return (1 - w) * low(shgc) + w * high(shgc)


# EnergyPlus's simple glazing system: the transmittance relative to its value at normal incidence,
# as quartics in cos(angle) without a constant term (Engineering Reference, "Simple Window Model",
# angular dependence; WindowManager.cc, TransAndReflAtPhi): coefficients of c^4, c^3, c^2, c, 1
SIMPLE_TRANSMITTANCE_CURVES = {
    "A": (0.01, 1.49, -3.85, 3.36, 0.0),
    "B": (0.55, 0.04, -2.42, 2.83, 0.0),
    "C": (0.77, -0.64, -1.58, 2.45, 0.0),
    "D": (0.35, 0.40, -2.58, 2.85, 0.0),
    "E": (2.88, -5.87, 2.49, 1.51, 0.0),
    "F": (3.03, -6.37, 3.14, 1.21, 0.0),
    "G": (3.23, -6.84, 3.54, 1.09, 0.0),
    "H": (3.33, -7.13, 3.83, 0.98, 0.0),
    "I": (3.15, -6.86, 3.93, 0.79, 0.0),
    "J": (3.74, -8.84, 6.02, 0.08, 0.0),
}


# ... and the reflectance's, each less the transmittance curve of its letter (WindowManager.cc,
# TransAndReflAtPhi): coefficients of c^4, c^3, c^2, c, 1
SIMPLE_REFLECTANCE_CURVES = {
    "A": (1.33, -3.20, 2.57, -0.70, 1.0),
    "B": (3.23, -7.86, 6.50, -1.87, 1.0),
    "C": (3.99, -9.86, 8.40, -2.52, 1.0),
    "D": (3.11, -7.64, 6.40, -1.85, 1.0),
    "E": (2.80, -6.82, 5.60, -1.57, 1.0),
    "F": (5.32, -13.14, 10.98, -3.15, 1.0),
    "G": (5.49, -13.54, 11.32, -3.25, 1.0),
    "H": (5.64, -13.94, 11.70, -3.39, 1.0),
    "I": (6.27, -15.74, 13.55, -4.06, 1.0),
    "J": (6.39, -16.32, 14.27, -4.35, 1.0),
}


def _cosine(angle):
    return np.cos(np.radians(np.asarray(angle, dtype=float)))


def simple_glazing_curve(U, shgc, angle):
    """The transmittance of EnergyPlus's simple glazing system of U-factor U (W/m2/K) and SHGC (-)
    at an angle of incidence (deg) relative to its normal-incidence one (-), unbounded: the curve
    of SIMPLE_TRANSMITTANCE_CURVES its (U, SHGC) region takes (`_simple_glazing_region`). 1 at
    normal incidence exactly."""
    c = _cosine(angle)
    value = {k: np.polyval(p, c) for k, p in SIMPLE_TRANSMITTANCE_CURVES.items()}
    return np.where(c == 1.0, 1.0, _simple_glazing_region(U, shgc, value))


def simple_glazing_reflectance_curve(U, shgc, angle):
    """How far the simple glazing system's reflectance at an angle of incidence (deg) has moved from
    its normal value towards 1 (-): R(angle) = R0 (1 - r) + r, r this curve, the reflectance curve
    of its (U, SHGC) region (SIMPLE_REFLECTANCE_CURVES less the transmittance curve of the same
    letter, as EnergyPlus writes them). 0 at normal incidence exactly."""
    c = _cosine(angle)
    value = {k: np.polyval(p, c) - np.polyval(SIMPLE_TRANSMITTANCE_CURVES[k], c)
             for k, p in SIMPLE_REFLECTANCE_CURVES.items()}
    return np.where(c == 1.0, 0.0, _simple_glazing_region(U, shgc, value))


def _simple_glazing_region(U, shgc, value):
    """The curve of the (U, SHGC) region of the Engineering Reference's map for EnergyPlus's simple
    glazing system of U-factor U (W/m2/K) and SHGC (-), from `value` {curve A to J: its values}, or
    between the curves of the neighbouring regions, linearly in U or SHGC or both (WindowManager.cc,
    TransAndReflAtPhi, cells 1 to 28). FGHI is the mean of F, G, H and I; FH of F and H; BDCD of
    B, D, C and D (twice D, as EnergyPlus has it)."""
    E, J, A, D = value["E"], value["J"], value["A"], value["D"]
    FGHI = (value["F"] + value["G"] + value["H"] + value["I"]) / 4.0
    FH = (value["F"] + value["H"]) / 2.0
    BDCD = (value["B"] + value["D"] + value["C"] + value["D"]) / 4.0

    def along(x, x0, x1, f0, f1):
        return f0 + (x - x0) / (x1 - x0) * (f1 - f0)

    def across(s0, s1, f00, f01, f10, f11, u0, u1):
        """Bilinear in (U, SHGC) between (u0, s0), (u0, s1), (u1, s0), (u1, s1)."""
        w = (u1 - u0) * (s1 - s0)
        return (f00 * (u1 - U) * (s1 - shgc) + f10 * (U - u0) * (s1 - shgc) + f01 * (u1 - U) * (shgc - s0)
                + f11 * (U - u0) * (shgc - s0)) / w

    if U < 1.4195:
        f = E if shgc > 0.45 else along(shgc, 0.35, 0.45, J, E) if shgc >= 0.35 else J
    elif U <= 1.7034:
        u = (1.4195, 1.7034)
        if shgc > 0.55:
            f = E
        elif shgc > 0.5:
            f = across(0.5, 0.55, E, E, FGHI, E, *u)
        elif shgc > 0.45:
            f = along(U, *u, E, FGHI)
        elif shgc > 0.35:
            f = across(0.35, 0.45, J, E, FGHI, FGHI, *u)
        elif shgc > 0.3:
            f = along(U, *u, J, FGHI)
        elif shgc > 0.25:
            f = across(0.25, 0.3, J, J, FH, FGHI, *u)
        else:
            f = along(U, *u, J, FH)
    elif U < 3.4068:
        if shgc > 0.55:
            f = E
        elif shgc >= 0.5:
            f = along(shgc, 0.5, 0.55, FGHI, E)
        elif shgc > 0.3:
            f = FGHI
        elif shgc >= 0.25:
            f = along(shgc, 0.25, 0.3, FH, FGHI)
        else:
            f = FH
    elif U <= 4.5424:
        u = (3.4068, 4.5424)
        if shgc > 0.65:
            f = along(U, *u, E, A)
        elif shgc > 0.6:
            f = across(0.6, 0.65, E, E, BDCD, A, *u)
        elif shgc > 0.55:
            f = along(U, *u, E, BDCD)
        elif shgc > 0.5:
            f = across(0.5, 0.55, FGHI, E, BDCD, BDCD, *u)
        elif shgc > 0.45:
            f = along(U, *u, FGHI, BDCD)
        elif shgc > 0.3:
            f = across(0.3, 0.45, FGHI, FGHI, D, BDCD, *u)
        elif shgc > 0.25:
            f = across(0.25, 0.3, FH, FGHI, D, D, *u)
        else:
            f = along(U, *u, FH, D)
    else:
        if shgc > 0.65:
            f = A
        elif shgc >= 0.6:
            f = along(shgc, 0.6, 0.65, BDCD, A)
        elif shgc > 0.45:
            f = BDCD
        elif shgc >= 0.3:
            f = along(shgc, 0.3, 0.45, D, BDCD)
        else:
            f = D
    return f


def simple_glazing_factors(U, shgc, angle):
    """The simple glazing system's transmittance at an angle of incidence (deg) relative to its
    normal-incidence T (`simple_glazing_transmittance`): T f_T(angle) held within 0..1, as
    EnergyPlus holds it, over T (-)."""
    tau = simple_glazing_transmittance(U, shgc)
    return np.clip(tau * simple_glazing_curve(U, shgc, angle), 0.0, 1.0) / tau


def simple_glazing_films(U):
    """(h_inside, h_outside) W/m2/K that EnergyPlus's simple glazing model takes its U-factor (W/m2/K)
    to include (Engineering Reference, "Simple Window Model", step 2)."""
    h_in = 0.359073 * np.log(U) + 6.949915 if U < 5.85 else 1.788041 * U - 2.886625
    return float(h_in), 0.025342 * U + 29.163853


def simple_glazing_absorptance(U, shgc):
    """Solar absorptance of EnergyPlus's simple glazing system's equivalent layer (Engineering
    Reference, "Simple Window Model", step 4): (SHGC - T) / Fr_in, the inward-flowing fraction
    Fr_in = (R_o,s + R_l / 2) / (R_o,s + R_l + R_i,s) of what the layer absorbs at its middle, R_l the
    layer's resistance left by U and step 2's films, R_o,s and R_i,s the films of the solar
    (summer) condition as functions of SHGC - T."""
    tau = simple_glazing_transmittance(U, shgc)
    x = max(shgc - tau, 0.0)
    h_in, h_out = simple_glazing_films(U)
    R_l = 1 / U - 1 / h_in - 1 / h_out
    R_is = 1 / (29.436546 * x ** 3 - 21.943415 * x ** 2 + 9.945872 * x + 7.426151)
    R_os = 1 / (2.225824 * x + 20.57708)
    inward = (R_os + 0.5 * R_l) / (R_os + R_l + R_is)
    return min(1.0 - tau, x / inward)


def simple_glazing_angular_absorptance(U, shgc, angle):
    """The solar absorptance (-) of EnergyPlus's simple glazing system's one layer at an angle of
    incidence (deg): 1 - T(angle) - R(angle), T = T0 f_T held within 0..1 (`simple_glazing_factors`)
    and R = R0 (1 - r) + r (`simple_glazing_reflectance_curve`) held within 0..0.9999 - T, R0 = 1 - T0
    - alpha0 (`simple_glazing_absorptance`), as EnergyPlus takes them (WindowManager.cc,
    TransAndReflAtPhi). alpha0 at normal incidence."""
    tau = simple_glazing_transmittance(U, shgc)
    T = tau * simple_glazing_factors(U, shgc, angle)
    R0 = 1.0 - tau - simple_glazing_absorptance(U, shgc)
    r = simple_glazing_reflectance_curve(U, shgc, angle)
    R = np.clip(R0 * (1.0 - r) + r, 0.0, np.maximum(0.9999 - T, 0.0))
    return 1.0 - T - R


def pane_absorptances(panes):
    """Solar absorptance of each pane of a stack (outside first) at normal incidence, each
    (T0, R0) the same on both faces, of the sun falling on the outermost pane: with f_k and b_k
    the flux falling on pane k from outside and from inside, f_1 = 1 and b_N = 0,

        f_k+1 = T_k f_k + R_k b_k,    b_k-1 = T_k b_k + R_k f_k,    A_k = (1 - T_k - R_k)(f_k + b_k)

    every interreflection counted (a linear system of the 2N fluxes)."""
    n = len(panes)
    # unknowns: f_1..f_N, b_1..b_N
    M, v = np.zeros((2 * n, 2 * n)), np.zeros(2 * n)
    M[0, 0], v[0] = 1.0, 1.0  # f_1 = 1
    M[1, 2 * n - 1] = 1.0  # b_N = 0
    row = 2
    for k, (T, R) in enumerate(panes):
        if k + 1 < n:  # f_k+1 = T f_k + R b_k
            M[row, k + 1], M[row, k], M[row, n + k] = 1.0, -T, -R
            row += 1
        if k > 0:  # b_k-1 = T b_k + R f_k
            M[row, n + k - 1], M[row, n + k], M[row, k] = 1.0, -T, -R
            row += 1
    flux = np.linalg.solve(M, v)
    return [(1 - T - R) * (flux[k] + flux[n + k]) for k, (T, R) in enumerate(panes)]


def angular_pane_absorptances(panes, angles):
    """(len(angles), N) solar absorptance of each pane of a stack (outside first, each (T0, R0) at
    normal incidence, the same on both faces) of the direct sun at each angle of incidence (deg):
    `pane_absorptances` of the panes' (T, R) at that angle (`pane_at`); 0 at grazing incidence,
    where every pane reflects all."""
    rows = []
    for angle in np.atleast_1d(np.asarray(angles, dtype=float)):
        if angle >= 90.0 - 1e-9:
            rows.append([0.0] * len(panes))
        else:
            rows.append(pane_absorptances([tuple(float(x) for x in pane_at(T0, R0, angle)) for T0, R0 in panes]))
    return np.array(rows)
