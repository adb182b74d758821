"""The catalogue of the benchmark's records: its scenarios (a building under a climate, measured
for some days by some sensors), its faults, and which of them each scenario carries (`PLAN`),
each record a `Spec` named `<scenario>/<fault>-<size>`."""
import dataclasses
from dataclasses import dataclass, fields

BURN_IN_DAYS = 1  # the diagnosis' (the command line's default)
CALIBRATION_FRACTION = 0.6  # the diagnosis' default: the rest validates


@dataclass(frozen=True)
class Fault:
    """What a record's file lacks: an effect (a registry id, or beyond the catalogue
    "scheduled_gain": W `full["Q"]` from `full["on"]` to `full["off"]` h local time; "opening":
    `full["area"]` m2 of glazing on the component `target`, its sun to the floor;
    "envelope_films": the zone `target`'s envelope materials and outside film coefficients both
    `full["factor"]` times the file's), its target (a zone, a component, `zone->column`), its
    parameters at scale 1 (others as declared) and the (effect, target) pairs a right answer may
    name (default: (effect, target)): look-alikes that are one equation count as one (an air
    change and a bridge to the outdoor air)."""
    effect: str
    target: str
    full: dict
    expected: tuple = ()

    @property
    def answers(self):
        """The (effect, target) pairs that name this fault."""
        return tuple(self.expected) or ((self.effect, self.target),)

    @property
    def label(self):
        return f"{self.effect}@{self.target}"


GROUND_FIELDS = ("declares_ground", "ground_offset")  # `Spec`'s, printed only where set


@dataclass(frozen=True)
class Spec:
    """One record: where, when, how measured, and what the file lacks (`faults`: none, one, or
    two together, each moved from the file's values towards its `full` by one common scale)."""
    name: str
    building: str  # "testcell" or "twinhouse"
    climate: str
    start: str  # month-day of the record's first time, in the climate's typical year
    days: int
    step_min: int
    noise: float  # C
    sensors: str  # "paper", "all", "air" (the test cell's air with a PRBS heater) or "own" (the file's sensors)
    faults: tuple = ()  # Fault
    size: str = ""  # "subtle", "strong", "" (no fault)
    objective: str = ""  # zone whose air is the objective (default the first)
    burn_in: int = BURN_IN_DAYS  # days the diagnosis forces every measured node and scores nothing
    before: float = 14.0  # days of the weather before the record the diagnosis reads (its history)
    declares_ground: bool = True  # the file declares the site's ground temperature (the typical year's mean air)
    ground_offset: float | None = None  # K: a ground fault's T_ground from the record's mean outdoor air

    def __hash__(self):  # a fault's `full` is a dict: the record's name and fields, as printed, identify it
        return hash(repr(self))

    def __repr__(self):
        """The dataclass's own form, the ground's fields printed only where they differ from their
        defaults: a record's digest (`bench_diagnosis.spec_digest`) is its repr, and the records
        that do not set them keep theirs."""
        shown = [f for f in fields(self) if f.name not in GROUND_FIELDS or getattr(self, f.name) != f.default]
        return f"Spec({', '.join(f'{f.name}={getattr(self, f.name)!r}' for f in shown)})"

    @property
    def answers(self):
        """The (effect, target) pairs counted right as a first effect: those of any of its faults."""
        return tuple(a for f in self.faults for a in f.answers)

    @property
    def label(self):
        """"none", or the faults, "effect@target + ..."."""
        return " + ".join(f.label for f in self.faults) or "none"


@dataclass(frozen=True)
class Scenario:
    """A building under a climate, measured: its file ("testcell" or "twinhouse"), the typical
    year, the record's first month-day, days and step (min), the sensors' noise (C) and set
    (`Spec.sensors`), the objective zone ("": the first), the diagnosis' burn-in, the days of
    weather before the record it reads and whether its file declares the site's ground
    temperature (`Spec`'s fields of the same names)."""
    building: str
    climate: str
    start: str
    days: int
    step_min: int
    noise: float
    sensors: str
    objective: str
    burn_in: int
    before: float
    declares_ground: bool = True


# -- the benchmark's records ----------------------------------------------------------------
# Scenarios: (building, climate, start, days, step min, noise C, sensors, objective, burn-in days,
# days of weather before the record the diagnosis reads). The look-alikes sit side by side in one
# scenario (an air change, a bridge, an envelope factor, inside convection; a door and a wall),
# each size of each effect appears somewhere, every scenario has a record without a fault. The
# Twin House's walls are heavy and none is measured: its burn-in is `make twinhouse`'s three days,
# and its weather starts six days before the record, as the real experiment 1's file does. The
# weather before the record varies as users' files do: six weeks, a month, a fortnight or a week
# before the measurements, three days, or none (the file starts with them).
SCENARIOS = {
    "mia-jun": Scenario("testcell", "miami", "06-01", 7, 15, 0.1, "paper", "", 1, 14),
    "gso-jan": Scenario("testcell", "greensboro", "01-10", 14, 30, 0.2, "all", "", 1, 30),
    "sdp-jul": Scenario("testcell", "sandpoint", "07-05", 10, 10, 0.05, "paper", "", 1, 14),
    "gso-apr": Scenario("testcell", "greensboro", "04-01", 21, 60, 0.3, "paper", "", 1, 0),
    "mia-dec": Scenario("testcell", "miami", "12-01", 5, 20, 0.15, "all", "", 1, 7),
    "sdp-feb-air": Scenario("testcell", "sandpoint", "02-01", 14, 30, 0.15, "air", "", 1, 45),
    "mia-jan-air": Scenario("testcell", "miami", "01-15", 7, 10, 0.25, "air", "", 1, 3),
    "twin-gso-feb": Scenario("twinhouse", "greensboro", "02-01", 14, 30, 0.15, "own", "living", 3, 6),
    # The deep ground 5 to 9 K either side of the record's mean outdoor air (`GROUND_OFFSET`), one
    # scenario a season under three climates, the diagnosis' prior on it from each of its sources
    # (`model.effects.deep_ground_temperature`): the file's declared ground temperature (July), a
    # year of weather before the record (April), neither: the records' own mean air (February, November)
    "gso-feb-ground": Scenario("testcell", "greensboro", "02-05", 10, 20, 0.1, "paper", "", 1, 14, declares_ground=False),
    "sdp-apr-ground": Scenario("testcell", "sandpoint", "04-10", 10, 30, 0.1, "all", "", 1, 365, declares_ground=False),
    "gso-jul-ground": Scenario("testcell", "greensboro", "07-15", 7, 15, 0.1, "paper", "", 1, 14),
    "mia-nov-ground": Scenario("testcell", "miami", "11-01", 10, 30, 0.1, "paper", "", 1, 21, declares_ground=False),
    # The start: the same autumn week, the air 6 K colder than the month before, read with none,
    # three or seven days of the weather before it, and measured by the air alone: no sensor's
    # burn-in sets the floor's slow mode (14.7 days), whose steady start puts the validation RMSE of
    # the file without a fault at 2.4 to 2.9 times the noise: the faults are strong
    "gso-oct-h0": Scenario("testcell", "greensboro", "10-20", 7, 20, 0.1, "air", "", 1, 0),
    "gso-oct-h3": Scenario("testcell", "greensboro", "10-20", 7, 20, 0.1, "air", "", 1, 3),
    "gso-oct-h7": Scenario("testcell", "greensboro", "10-20", 7, 20, 0.1, "air", "", 1, 7),
}
AIR_OUT = (("infiltration", "cell"), ("thermal_bridge", "cell"))  # one equation: a conductance air -> outdoor air
FAULTS = {  # name: Fault
    "ground": Fault("ground_coupling", "floor", {"U": 3.0, "T_ground": None}, ()),
    "infiltration": Fault("infiltration", "cell", {"n": 2.0}, AIR_OUT),
    "bridge": Fault("thermal_bridge", "cell", {"UA": 15.0}, AIR_OUT),
    # the envelope's materials more conductive than declared (the registry's effect), and the
    # materials with the outside films (the truth's file edited): both the zone's envelope, not one
    # of its components. Films scaled with the layers keep the share of the absorbed sun that
    # reaches the zone (about U / h_o) as declared: the zone then loses heat as through a
    # conductance from its air to the outdoor air, which the sun alone tells from it (at equal
    # HLC the air's steady response to the sun on every face is 0.0364 K per W/m2 for this fault,
    # 0.0376 for an air change, 0.0413 for the materials), so that conductance is a right answer too
    "envelope": Fault("envelope_conductance", "cell", {"factor": 2.0}, ()),
    "envelope-films": Fault("envelope_films", "cell", {"factor": 2.0}, (("envelope_conductance", "cell"),) + AIR_OUT),
    # weaker inside convection: a factor up to the registry's 20 never makes a strong error in the cell
    "convection": Fault("inside_convection", "cell", {"factor": 0.4}, ()),
    "door": Fault("conductivity", "door", {"factor": 3.0}, ()),
    "wall": Fault("conductivity", "east_wall", {"factor": 3.0}, ()),
    "roof-alpha": Fault("solar_absorptance", "roof", {"alpha": 0.9}, ()),
    "window-tau": Fault("solar_transmittance", "window", {"tau": 0.3}, ()),
    "gain": Fault("internal_gain", "cell", {"Q": 100.0}, ()),
    "daily": Fault("daily_gain", "cell", {"mean": 80.0, "cos1": -60.0, "sin1": -40.0, "cos2": 20.0}, ()),
    "east-sun": Fault("proportional_gain", "cell->I_east_wall", {"k": 0.5}, ()),
    "mass": Fault("internal_mass", "cell", {"C_m": 4e5, "H_m": 25.0}, ()),
    "lag": Fault("heat_input_lag", "cell", {"C_h": 1.2e5, "H_h": 15.0}, ()),
    "split": Fault("heat_input_split", "cell", {"f_r": 0.8}, ()),
    "schedule": Fault("scheduled_gain", "cell", {"Q": 150.0, "on": 8.0, "off": 18.0}, (("daily_gain", "cell"),)),
    "opening": Fault("opening", "south_wall", {"area": 0.6},
                (("proportional_gain", "cell->I_south_wall"), ("solar_transmittance", "window"))),
    # the Twin House's living room
    "W8": Fault("conductivity", "W8", {"factor": 2.0}, ()),
    "shading": Fault("shading_transmittance", "living", {"f": 0.3}, ()),
    "living-mass": Fault("internal_mass", "living", {"C_m": 1.5e6, "H_m": 150.0}, ()),
}
GROUND = {"mia-jun": 24.0, "mia-dec": 15.0, "sdp-jul": 5.0}  # C, the ground below the cell, away from its air
# K, the truth's deep ground (the ground fault's T_ground) from the record's mean outdoor air
# (`truth.record_mean_air`), of either sign in each season. The sun keeps the cell 1 to 4 K above
# the outdoor air: a ground above that air is near the floor's own temperature, and its coupling,
# whatever its U, leaves the file an error of 2 to 3 times the noise at most; the strong records'
# ground is below it.
GROUND_OFFSET = {"gso-feb-ground/ground-s": 8.0, "gso-feb-ground/ground-L": -9.0,
                 "sdp-apr-ground/ground-s": 7.0, "sdp-apr-ground/ground-L": -9.0,
                 "gso-jul-ground/ground-s": 9.0, "gso-jul-ground/ground-L": -9.0,
                 "mia-nov-ground/ground-s": 9.0, "mia-nov-ground/ground-L": -8.0}
# Two faults together (`a+b`): a component whose inside surface a sensor reads and an effect no
# sensor reads (a component without one, the zone's air), at steps of 10 to 60 min; both must
# be found.
PLAN = {  # scenario: [fault, or faults joined by "+", or "none"; size "s" subtle / "L" strong]
    "mia-jun": ["none", "infiltration s", "bridge s", "envelope s", "envelope-films s", "convection s", "door s",
                "wall s", "ground s", "schedule s", "opening s", "door+roof-alpha s"],
    # every node measured in winter: the door (1.6 m2) ten times as conductive, or the inside
    # convection a tenth, the most physics allows (`max_scale`), stay subtle here
    "gso-jan": ["none", "infiltration L", "bridge L", "envelope L", "convection s", "door s", "wall L",
                "roof-alpha s", "window-tau s", "mass s"],
    "sdp-jul": ["none", "ground L", "roof-alpha L", "window-tau L", "gain s", "daily s", "east-sun s",
                "schedule L", "opening L", "door+window-tau L"],
    "gso-apr": ["none", "gain L", "daily L", "east-sun L", "mass L", "infiltration s", "envelope s", "convection s",
                "wall+infiltration L"],
    "mia-dec": ["none", "door s", "wall s", "ground s", "bridge s", "opening s", "schedule s", "door+bridge s"],
    "sdp-feb-air": ["none", "lag s", "split L", "mass s", "envelope L", "envelope-films L", "infiltration L",
                    "convection L", "gain s"],
    "mia-jan-air": ["none", "lag L", "split s", "mass L", "envelope s", "envelope-films s", "schedule L"],
    # a Twin House diagnosis takes some 20 times a test cell's (docs/benchmark_diagnosis.md): four records
    # (and 100 air capacities of furniture, the registry's bound, stay subtle)
    "twin-gso-feb": ["none", "W8 L", "shading s", "living-mass s"],
    **{name: ["none", "ground s", "ground L"] for name in ("gso-feb-ground", "sdp-apr-ground", "gso-jul-ground",
                                                           "mia-nov-ground")},
    **{name: ["none", "gain L", "infiltration L"] for name in ("gso-oct-h0", "gso-oct-h3", "gso-oct-h7")},
}


def make_specs():
    """Every record of the benchmark, named `<scenario>/<fault>[+<fault>]-<size>`."""
    specs = []
    for scenario, entries in PLAN.items():
        common = {f.name: getattr(SCENARIOS[scenario], f.name) for f in fields(Scenario)}
        for entry in entries:
            names, _, size = entry.partition(" ")
            if names == "none":
                specs.append(Spec(name=f"{scenario}/none", **common))
                continue
            name = f"{scenario}/{names}-{size}"
            # a ground at the scenario's temperature, or (T_ground None) at the record's offset
            faults = tuple(dataclasses.replace(FAULTS[n], full={**FAULTS[n].full, "T_ground": GROUND.get(scenario)})
                           if "T_ground" in FAULTS[n].full else FAULTS[n] for n in names.split("+"))
            specs.append(Spec(name=name, faults=faults, size={"s": "subtle", "L": "strong"}[size],
                              ground_offset=GROUND_OFFSET.get(name), **common))
    return specs

SPECS = make_specs()
SPECS_BY_NAME = {s.name: s for s in SPECS}
QUICK = ("mia-jun/none", "mia-jun/door-s", "gso-jan/infiltration-L", "sdp-jul/schedule-L", "sdp-feb-air/lag-s",
         "mia-dec/opening-s", "gso-apr/mass-L", "twin-gso-feb/W8-L")


def quick_specs():
    """Eight records across the scenarios, sizes and sensor sets, for development (`--quick`)."""
    return [SPECS_BY_NAME[name] for name in QUICK]
