"""One noise yardstick and one pass rule (`model.score.Yardstick`), read by the forcing search's
parsimony (`ga.parsimony`) and the diagnosis' choice (`diagnosis.policy.Policy`) alike."""
import numpy as np
import pytest

from nodeforce.diagnosis.policy import Policy
from nodeforce.ga import parsimony
from nodeforce.model.score import Yardstick


def test_the_search_and_the_choice_read_one_yardstick():
    policy = Policy()
    assert policy.yardstick == Yardstick()
    for J, sd, n in ((100.0, 0.1, 1000), (100.0, None, 1000), (1e-6, 0.01, 96)):
        assert parsimony.tolerance(J, sd, n) == policy.least_fall(J, sd, n)
        assert parsimony.noise_tolerance(sd, n) == policy.noise_change(sd, n)
        assert parsimony.noise_J(sd, n) == policy.noise_J(sd, n)
    # a yardstick changed in one place changes both
    strict = Yardstick(noise_sds=6.0)
    assert parsimony.tolerance(1.0, 0.1, 1000, strict) == Policy(yardstick=strict).least_fall(1.0, 0.1, 1000) \
        == pytest.approx(2 * parsimony.tolerance(1.0, 0.1, 1000))
    # no module keeps a copy of its constants
    assert not {"Z_NOISE", "RELATIVE_FLOOR", "ROUNDING"} & set(vars(parsimony))


def test_the_pass_rule_beats_its_need_on_more_days_than_its_best():
    rule = Yardstick()
    steady = rule.judge([10.0, 10.0, 10.0], [8.0, 8.1, 7.9], least=1.0)
    assert steady.fall == pytest.approx(6.0) and steady.beats and not steady.reversed
    assert steady.needed == max(1.0, steady.se)
    one_day = rule.judge([10.0, 10.0, 10.0], [2.0, 10.5, 10.5], least=1.0)  # all of it from one day
    assert one_day.fall > 1.0 and one_day.other_days < 0 and not one_day.beats
    below = rule.judge([10.0, 10.0], [9.9, 9.9], least=1.0)
    assert not below.beats
    worse = rule.judge([10.0, 10.0], [12.0, 12.0], least=1.0)
    assert worse.reversed and not worse.beats
    scattered = rule.judge([10.0, 10.0, 10.0, 10.0], [4.0, 11.0, 9.0, 10.5], least=0.1)  # se beyond its fall
    assert scattered.needed == pytest.approx(np.sqrt(4) * np.std([6.0, -1.0, 1.0, -0.5], ddof=1))
    assert not scattered.beats
