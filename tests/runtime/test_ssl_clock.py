"""Match time <-> the Unix time of the league's wire: the referee's microseconds and the log's
nanoseconds cross exactly both ways, a sender's clock from 0 (grSim's) is taken as match time, the
run's epoch is one value for the run."""

from __future__ import annotations

import pytest

from cmdragons.runtime.ssl.clock import UnixEpoch, run_epoch

E = UnixEpoch(1_764_000_000)


@pytest.mark.parametrize("t", [0.0, 1 / 60, 41.5, 187.123456, 3599.999999])
def test_microseconds_and_nanoseconds_cross_exactly(t: float) -> None:
    assert E.to_unix_us(t) == 1_764_000_000 * 10**6 + round(t * 1e6)
    assert E.from_unix_us(E.to_unix_us(t)) == round(t * 1e6) / 1e6  # as the match-time microseconds read
    assert E.from_unix_ns(E.to_unix_ns(t)) == round(t * 1e9) / 1e9
    assert E.to_match(E.to_unix(t)) == pytest.approx(t, abs=3e-7)  # a double near 1.8e9 s: 0.24 µs steps


def test_the_epoch_of_a_senders_first_time() -> None:
    assert UnixEpoch.of_first(1_764_000_000.73) == E  # SSL-Vision, the game controller: Unix time
    # grSim stamps its frames with its simulation time: how long it ran before is no match time
    assert UnixEpoch.of_first(47.6) == UnixEpoch(47)


def test_the_runs_epoch_is_a_whole_second_and_stays() -> None:
    first = run_epoch()
    assert first.epoch_s == int(first.epoch_s) and run_epoch() is first
