"""One calibrated parameter as the diagnosis reads it (`ParameterEstimate`), and as report.json
writes it ({"value", "std", "identifiable", "on_bound"} and "prior" where it has one)."""
from dataclasses import dataclass


@dataclass(frozen=True)
class ParameterEstimate:
    """A parameter of a calibrated effect (`diagnosis.calibrate`): its `value`, its standard
    deviation `sd` (report.json's "std", the posterior's where it has a prior), whether the data
    alone identify it, whether it ended on a bound of its search range (`on_bound`), and `prior`,
    the physical prior the fit weighed with the data, stated (`calibrate.stated`; None: none)."""
    value: float
    sd: float
    identifiable: bool
    on_bound: bool = False
    prior: str | None = None

    @classmethod
    def of(cls, p):
        """From report.json's form (a dict), or the estimate itself."""
        if isinstance(p, cls):
            return p
        return cls(p["value"], p["std"], p["identifiable"], bool(p.get("on_bound", False)), p.get("prior") or None)

    def to_json(self):
        """report.json's form: {"value", "std", "identifiable", "on_bound"}, and "prior" where it has one."""
        return {"value": self.value, "std": self.sd, "identifiable": self.identifiable, "on_bound": self.on_bound,
                **({"prior": self.prior} if self.prior else {})}


def estimates(parameters):
    """{name: ParameterEstimate} of {name: report.json's form or an estimate}."""
    return {name: ParameterEstimate.of(p) for name, p in (parameters or {}).items()}


def estimates_json(parameters):
    """{name: report.json's form} of {name: ParameterEstimate}."""
    return {name: p.to_json() for name, p in parameters.items()}
