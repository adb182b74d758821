"""Internal gains as EnergyPlus defines them (docs/model.md section 3.4)."""
import numpy as np

# EnergyPlus's sensible heat of a person (Engineering Reference, "People"), a polynomial of the
# activity level M (W) and the zone's air temperature T (C), its coefficients in this order:
# 1, M, M^2, T, T M, T M^2, T^2, T^2 M, T^2 M^2
PEOPLE_SENSIBLE = (6.461927, 0.946892, 0.0000255737, 7.139322, -0.0627909, 0.0000589172, -0.198550, 0.000940018,
                   -0.00000149532)
# The zone temperature (C) about which a converted model linearises a person's sensible heat
# (the building file's gain and its temperature slope)
PEOPLE_T = 24.0


def people_sensible_heat(activity, T=PEOPLE_T):
    """Sensible heat of one person (W) at an activity level (W) and an air temperature (C),
    within 0 and the activity level, where EnergyPlus bounds it (InternalHeatGains.cc); numpy
    arrays alike."""
    c = PEOPLE_SENSIBLE
    M = activity
    heat = (c[0] + c[1] * M + c[2] * M ** 2 + T * (c[3] + c[4] * M + c[5] * M ** 2)
            + T ** 2 * (c[6] + c[7] * M + c[8] * M ** 2))
    return np.minimum(np.maximum(heat, 0.0), M)


def people_sensible_slope(activity, T=PEOPLE_T):
    """d(sensible heat)/dT of one person (W/K) at an activity level (W) and an air temperature
    (C): the polynomial's derivative, 0 where the bounds hold it."""
    c = PEOPLE_SENSIBLE
    M = activity
    if not 0.0 < people_sensible_heat(activity, T) < M:
        return 0.0
    return c[3] + c[4] * M + c[5] * M ** 2 + 2 * T * (c[6] + c[7] * M + c[8] * M ** 2)
