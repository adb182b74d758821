"""Exterior convection as EnergyPlus's DOE-2 model gives it (Engineering Reference, "Outside
Surface Heat Balance", DOE-2 model), evaluated once at a reference wind for the constant
coefficient a building file holds (docs/model.md section 3.2). Speeds in m/s, heights in m,
coefficients in W/m2/K, angles in degrees.
"""
import numpy as np

# EnergyPlus's wind profile: (exponent alpha, boundary layer thickness delta m) of each terrain,
# and of the weather station's (open country, at 10 m)
TERRAIN = {"country": (0.14, 270.0), "suburbs": (0.22, 370.0), "city": (0.33, 460.0),
           "ocean": (0.10, 210.0), "urban": (0.22, 370.0)}
STATION_HEIGHT = 10.0
# Surface roughness multipliers R_f of the DOE-2 model (EnergyPlus's Material Roughness)
ROUGHNESS = {"veryrough": 2.17, "rough": 1.67, "mediumrough": 1.52, "mediumsmooth": 1.13, "smooth": 1.11,
             "verysmooth": 1.00}
# MoWiTT's forced convection on a smooth surface, h = a V^b, windward and leeward
WINDWARD, LEEWARD = (3.26, 0.89), (3.55, 0.617)


def wind_at_height(speed, height, terrain="country"):
    """V_z = V_met (delta_met / z_met)^alpha_met (z / delta)^alpha: the weather station's wind
    (at 10 m in open country) at a height z above the ground of a site's terrain."""
    alpha_met, delta_met = TERRAIN["country"]
    alpha, delta = TERRAIN[terrain.lower()]
    return speed * (delta_met / STATION_HEIGHT) ** alpha_met * (max(height, 0.0) / delta) ** alpha


def natural_convection(tilt, delta_T):
    """TARP's natural convection (W/m2/K) on a face of `tilt` deg at |T_s - T_air| = delta_T K:
    1.31 dT^(1/3) on a vertical face; on an inclined one the mean of the unstable (heat rising
    from it) 9.482 dT^(1/3) / (7.238 - |cos tilt|) and stable 1.810 dT^(1/3) / (1.382 + |cos tilt|)."""
    c = abs(np.cos(np.radians(tilt)))
    root = abs(delta_T) ** (1 / 3)
    if c < 1e-6:
        return 1.31 * root
    return 0.5 * (9.482 * root / (7.238 - c) + 1.810 * root / (1.382 + c))


def doe2(tilt, speed, roughness=1.0, delta_T=5.0, windward=None):
    """DOE-2's exterior convective coefficient h = h_n + R_f (h_glass - h_n), h_glass =
    sqrt(h_n^2 + (a V^b)^2), at the local wind V (m/s), for a roughness multiplier R_f; a face is
    windward or leeward as the wind turns, so, unless `windward` says which, the mean of the two
    (a roof, within 10 deg of horizontal, is windward, as EnergyPlus takes it)."""
    h_n = natural_convection(tilt, delta_T)

    def h(a, b):
        return h_n + roughness * (np.sqrt(h_n ** 2 + (a * speed ** b) ** 2) - h_n)

    if windward is None and tilt <= 10:
        windward = True
    if windward is None:
        return 0.5 * (h(*WINDWARD) + h(*LEEWARD))
    return h(*(WINDWARD if windward else LEEWARD))


def tarp_inside(tilt, delta_T, warmer=True):
    """TARP's natural convection (W/m2/K) on an inside face whose component's outside faces `tilt`
    deg (a floor 180: its inside face looks up), at |T_s - T_air| = delta_T K, the face `warmer`
    than the air or not: 1.31 dT^(1/3) on a wall; on a face looking up and warmer (or looking down
    and cooler) the unstable 9.482 dT^(1/3) / (7.238 - |cos|), else the stable
    1.810 dT^(1/3) / (1.382 + |cos|)."""
    c = abs(np.cos(np.radians(tilt)))
    root = abs(delta_T) ** (1 / 3)
    if c < 1e-6:
        return 1.31 * root
    looks_up = tilt > 90
    if looks_up == warmer:
        return 9.482 * root / (7.238 - c)
    return 1.810 * root / (1.382 + c)


# EnergyPlus's Simple inside algorithm: constant coefficients, W/m2/K (vertical; horizontal and
# tilted, unstable and stable)
SIMPLE_INSIDE = {"vertical": 3.076, "horizontal": (4.040, 0.948), "tilted": (3.870, 2.281)}


def simple_inside(tilt, warmer=True):
    """EnergyPlus's Simple inside coefficient of a face (arguments as `tarp_inside`)."""
    c = abs(np.cos(np.radians(tilt)))
    if c < 1e-6:
        return SIMPLE_INSIDE["vertical"]
    unstable, stable = SIMPLE_INSIDE["horizontal" if c > 0.99 else "tilted"]
    return unstable if (tilt > 90) == warmer else stable


# The steps' coefficients (docs/model.md section 3.6): the functions below take arrays of faces and
# are what the direct model, the Python FMU and, in C, model/c/steps.c evaluate at every step.

# EnergyPlus's floor on a face's inside coefficient (HeatBalanceAlgorithm's low limit), W/m2/K: a
# face at the air's temperature still exchanges a little
INSIDE_FLOOR = 0.1


def tarp_natural(delta_T, cos_up):
    """TARP's natural convection (W/m2/K) of faces at delta_T = T_s - T_air (K) whose normal into
    the air makes cos_up with the vertical (1 a face looking up, 0 a wall, -1 looking down):
    Walton's unstable 9.482 |dT|^(1/3) / (7.238 - |cos|) where the heat rises off the face (a warm
    face looking up, a cool one looking down), else the stable 1.810 |dT|^(1/3) / (1.382 + |cos|);
    on a wall (|cos| < 1e-6) ASHRAE's 1.31 |dT|^(1/3), which both come within 3e-4 of."""
    delta_T, cos_up = np.asarray(delta_T, dtype=float), np.asarray(cos_up, dtype=float)
    root, c = np.cbrt(np.abs(delta_T)), np.abs(cos_up)
    unstable = delta_T * cos_up > 0.0
    walton = np.where(unstable, 9.482 * root / (7.238 - c), 1.810 * root / (1.382 + c))
    return np.where(c < 1e-6, 1.31 * root, walton)


def tarp_inside_faces(delta_T, cos_up):
    """EnergyPlus's TARP inside coefficient (W/m2/K): `tarp_natural`, at least `INSIDE_FLOOR`."""
    return np.maximum(tarp_natural(delta_T, cos_up), INSIDE_FLOOR)


def iso15099_inside(delta_T, T_air, height, tilt, pressure=101325.0):
    """ISO 15099's inside convection (W/m2/K) of window faces, as EnergyPlus takes a window's where
    its zone's inside algorithm is TARP (ConvectionCoefficients.cc, CalcISO15099WindowIntConvCoeff;
    ISO 15099 section 8.3.2.2): h = Nu lambda / H at delta_T = T_s - T_air (K), the zone air at
    T_air (C), the window `height` H (m) and `tilt` (deg, its outside's: 90 vertical). The air's
    properties are taken at the film's T_f = T_air + dT / 4 (K): lambda = 2.873e-3 + 7.76e-5 T_f
    W/m/K, mu = 3.723e-6 + 4.94e-8 T_f kg/m/s (ISO 15099 Tables B.1, B.2), c_p = 1004.84 J/kg/K
    and rho = p / (287.05 T_f) kg/m3, dry air at the site's `pressure` p (Pa), as EnergyPlus
    takes its site's (it adds the zone's humidity, which moves h by some 0.1 %). With
    Ra = rho^2 H^3 g c_p |dT| / (T_f mu lambda) and theta the tilt, 180 - tilt where the face is
    warmer than the air (the heat then leaves it looking the other way):

        Nu = 0.13 Ra^(1/3)                                     theta < 15
        Nu = 0.56 (Ra sin tilt)^(1/4)                          15 <= theta <= 90, Ra <= Ra_cv
        Nu = 0.13 (Ra^(1/3) - Ra_cv^(1/3)) + 0.56 (Ra_cv sin tilt)^(1/4)   above it,
             Ra_cv = 2.5e5 (exp(0.72 theta) / sin tilt)^(1/5)
        Nu = 0.56 (Ra sin tilt)^(1/4), Ra sin tilt held within 1e5 .. 1e11   90 < theta <= 179
        Nu = 0.58 min(Ra, 1e11)^(1/5)                          theta > 179

    at least `INSIDE_FLOOR`. A vertical window is 0.56 Ra^(1/4) both ways."""
    delta_T, T_air = np.asarray(delta_T, dtype=float), np.asarray(T_air, dtype=float)
    tilt = np.asarray(tilt, dtype=float)
    T_f = T_air + 273.15 + 0.25 * delta_T  # K
    conductivity, viscosity = 2.873e-3 + 7.76e-5 * T_f, 3.723e-6 + 4.94e-8 * T_f
    rho = pressure / (287.05 * T_f)
    ra = rho ** 2 * height ** 3 * 9.81 * 1004.84 * np.abs(delta_T) / (T_f * viscosity * conductivity)
    theta = np.where(delta_T > 0.0, 180.0 - tilt, tilt)
    sine = np.maximum(np.sin(np.radians(tilt)), 1e-9)  # a horizontal window reads cases a and d alone
    with np.errstate(over="ignore"):
        ra_cv = 2.5e5 * (np.exp(0.72 * np.minimum(theta, 90.0)) / sine) ** 0.2
    tilted = np.where(ra <= ra_cv, 0.56 * (ra * sine) ** 0.25,
                      0.13 * (np.cbrt(ra) - np.cbrt(ra_cv)) + 0.56 * (ra_cv * sine) ** 0.25)
    nu = np.where(theta < 15.0, 0.13 * np.cbrt(ra),
                  np.where(theta <= 90.0, tilted,
                           np.where(theta <= 179.0, 0.56 * np.clip(ra * sine, 1e5, 1e11) ** 0.25,
                                    0.58 * np.minimum(ra, 1e11) ** 0.2)))
    return np.maximum(nu * conductivity / height, INSIDE_FLOOR)


def windward_faces(cos_up, azimuth, direction):
    """Whether faces (their normal's cos_up with the vertical, azimuth deg from north) are
    windward of a wind from `direction` (deg from north): as EnergyPlus takes it, a face within
    0.98 of horizontal always, any other where the wind comes from within 90 deg of its normal."""
    diff = np.abs(np.asarray(direction, dtype=float) - azimuth)
    diff = np.where(diff - 180.0 > 0.001, diff - 360.0, diff)
    return (np.abs(cos_up) >= 0.98) | (np.abs(diff) - 90.0 <= 0.001)


def doe2_faces(speed, windward, delta_T, cos_up, roughness):
    """DOE-2's exterior convective coefficient (W/m2/K) of faces at a local wind `speed` (m/s),
    windward or not, at delta_T = T_e - T_out (K), of roughness multipliers R_f:
    h = h_n + R_f (sqrt(h_n^2 + (a V^b)^2) - h_n), h_n `tarp_natural`, MoWiTT's (a, b) windward
    (3.26, 0.89) or leeward (3.55, 0.617)."""
    h_n = tarp_natural(delta_T, cos_up)
    speed = np.maximum(np.asarray(speed, dtype=float), 0.0)
    forced = np.where(windward, WINDWARD[0] * speed ** WINDWARD[1], LEEWARD[0] * speed ** LEEWARD[1])
    return h_n + roughness * (np.sqrt(h_n ** 2 + forced ** 2) - h_n)



def lagged_excess(h, h0, cap=None):
    """The part of a followed coefficient h (W/m2/K) the lagged source carries beside the h0 the
    step matrix holds: h - h0, at most `cap` (W/m2/K; h0 where none is given). An error e in a
    face's temperature then becomes (C/dt - (h - h0) A) e / (C/dt + h0 A + G) the next step, less
    than e whatever the face's capacity; uncapped, a face of little capacity grows its error once
    h - h0 exceeds h0 + G (a massless outer layer in a gale: EnergyPlus's 1ZoneEvapCooler roof
    overflowed within a day of Golden's wind). An outside face's convection is capped at h0 + 2
    C/(A dt) instead (`outside_cap`)."""
    return np.minimum(np.asarray(h, dtype=float) - h0, h0 if cap is None else cap)


def outside_cap(h0, area, capacity_rate):
    """The most an outside face's lagged convective excess may be (W/m2/K): h0 + 2 C/(A dt), for
    the face node's capacity over the sub-step C/dt (W/K, `capacity_rate`) and its area A (m2).
    The face's error e then becomes (C/dt - x A) e / (C/dt + (h0 + h_re) A + G) with x at most h0 +
    2 C/(A dt), which is more than -1; and the step's matrix plus the capacities twice less the
    excesses stays diagonally dominant, so that no mode of the network's error grows either (the
    face's long-wave excess is at most h_re). Capped at h0 alone, DOE-2's coefficient on a rough
    roof would be cut from some 8.5 m/s of station wind (h0 at 4 m/s), and a light roof's outer
    face run up to 3 K warm in the sun; with the capacity of 19 mm of wood at its face, over
    300-s sub-steps, the roof takes DOE-2's coefficient whole to some 18 m/s. A massless face (a
    window's outer pane) keeps the cap h0."""
    return h0 + 2.0 * capacity_rate / area
