"""Schedules of a building file (docs/model.md section 1.2): a value (no unit, or the unit of
what it drives: a fraction of a gain, a temperature in C) that follows the local clock, the day of
the week and the date, as EnergyPlus's Schedule:Year / Week / Day do.

A schedule is a constant, or day profiles and the periods of the year that use them: a profile is
[[until, value], ...] with `until` the hour (0 < until <= 24, increasing, the last 24) up to which
`value` holds; a period runs through a date ("MM-DD", the periods in order, the last "12-31")
with one profile name for each day of the week, Monday first.
"""
from dataclasses import dataclass

import numpy as np

WEEKDAYS = ("monday", "tuesday", "wednesday", "thursday", "friday", "saturday", "sunday")


@dataclass(frozen=True)
class Schedule:
    name: str
    constant: float | None = None
    days: tuple = ()  # (profile name, ((until h, value), ...))
    periods: tuple = ()  # ((month, day) through, (7 profile names, Monday first))

    @property
    def is_constant(self):
        """Whether it takes one value all year (declared constant, or every profile one value)."""
        return self.constant is not None or len({v for _, p in self.days for _, v in p}) == 1

    @property
    def value(self):
        """Its one value where `is_constant`."""
        return self.constant if self.constant is not None else self.days[0][1][0][1]

    def at(self, month, day, weekday, hour):
        """Values at local dates and clock times: `month` (1..12), `day` (1..31), `weekday` (0 Monday
        .. 6 Sunday), `hour` (0 <= h < 24), arrays of one shape. A value holds over (previous
        until, until]: the hour ending at 07:00 takes the value "until 07:00"; midnight the first."""
        if self.constant is not None:
            return np.full(np.shape(hour), float(self.constant))
        profiles = dict(self.days)
        month, day, weekday, hour = (np.asarray(a) for a in (month, day, weekday, hour))
        out = np.full(np.shape(hour), np.nan)
        date = month * 100 + day
        start = 0
        for (m, d), week in self.periods:
            in_period = (date > start) & (date <= m * 100 + d)
            for w, name in enumerate(week):
                rows = in_period & (weekday == w)
                if not rows.any():
                    continue
                untils = np.array([u for u, _ in profiles[name]])
                values = np.array([v for _, v in profiles[name]])
                k = np.searchsorted(untils, hour[rows], side="left")
                out[rows] = values[np.minimum(k, len(values) - 1)]
            start = m * 100 + d
        return out

    def on(self, times, timezone):
        """Values at tz-aware `times` (a pandas DatetimeIndex) read on the clock of `timezone`."""
        local = times.tz_convert(timezone)
        hour = local.hour + local.minute / 60 + local.second / 3600
        # the instant that ends a day (24:00) belongs to the day it ends
        midnight = np.asarray(hour) == 0
        shifted = local - np.where(midnight, 1, 0) * np.timedelta64(1, "s")
        hour = np.where(midnight, 24.0, hour)
        return self.at(np.asarray(shifted.month), np.asarray(shifted.day), np.asarray(shifted.day_of_week), hour)
