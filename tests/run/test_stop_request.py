"""The stop request of a run (hypothesis): a signal's number is kept until it is cleared, and what is no signal's
number is refused with a ConfigError naming ``signum`` before anything is kept. The profile is bounded and
derandomized, as in tests/api/test_properties.py."""

from __future__ import annotations

import math
import signal

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hhscatter.errors import ConfigError
from hhscatter.run import runner

PROFILE = settings(max_examples=40)  # the rest from the suite's profile (conftest.py)
SIGNALS = st.sampled_from(list(signal.Signals))
#: what is no signal's number: no int, a bool, or an int no named signal of this platform has
NOT_A_SIGNAL = st.one_of(
    st.none(),
    st.booleans(),
    st.text(max_size=4),
    st.floats(allow_nan=True, allow_infinity=True),
    st.just(np.float64(15.0)),
    st.just([15]),
    st.just({"signum": 15}),
    st.integers(-(2**70), 2**70).filter(lambda n: n not in {int(s) for s in signal.Signals}),
)


@pytest.fixture(autouse=True)
def _no_request_left():
    runner.clear_stop()
    yield
    runner.clear_stop()


@PROFILE
@given(signums=st.lists(SIGNALS, min_size=1, max_size=3))
def test_a_request_stops_the_run_until_it_is_cleared(signums):
    runner.clear_stop()
    for s in signums:
        runner.request_stop(s)
    with pytest.raises(KeyboardInterrupt, match=signal.Signals(signums[0]).name):
        runner._check_stop()
    runner.clear_stop()
    runner._check_stop()  # nothing left: the run goes on


@PROFILE
@given(bad=NOT_A_SIGNAL)
def test_what_is_no_signal_is_refused_and_not_kept(bad):
    runner.clear_stop()
    with pytest.raises(ConfigError, match="signum"):
        runner.request_stop(bad)
    runner._check_stop()  # the refused request left nothing behind


def test_the_refusal_comes_before_the_request_is_kept():
    runner.request_stop(signal.SIGINT)
    with pytest.raises(ConfigError, match="signum"):
        runner.request_stop(math.nan)
    with pytest.raises(KeyboardInterrupt, match="SIGINT"):
        runner._check_stop()
