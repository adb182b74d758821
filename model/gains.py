"""Internal gains as EnergyPlus defines them (docs/model.md section 3.4)."""

# EnergyPlus's sensible heat of a person (Engineering Reference, "People"), a polynomial of the
# activity level M (W) and the zone's air temperature T (C), its coefficients in this order:
# 1, M, M^2, T, T M, T M^2, T^2, T^2 M, T^2 M^2
PEOPLE_SENSIBLE = (6.461927, 0.946892, 0.0000255737, 7.139322, -0.0627909, 0.0000589172, -0.198550, 0.000940018,
                   -0.00000149532)
# The zone temperature (C) at which a converted model takes a person's sensible heat: the
# polynomial depends on it, the building file's gains do not
PEOPLE_T = 24.0


def people_sensible_heat(activity, T=PEOPLE_T):
    """Sensible heat of one person (W) at an activity level (W) and an air temperature (C)."""
    c = PEOPLE_SENSIBLE
    M = activity
    return (c[0] + c[1] * M + c[2] * M ** 2 + T * (c[3] + c[4] * M + c[5] * M ** 2)
            + T ** 2 * (c[6] + c[7] * M + c[8] * M ** 2))
