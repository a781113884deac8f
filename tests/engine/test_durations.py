"""Task times as distributions: sampling, the parameters an engineer or a sample gives, fitting."""

import math
import random
import statistics

import pytest

from hrc.engine.durations import (
    Duration,
    DurationError,
    Empirical,
    Fixed,
    Lognormal,
    Triangular,
    duration_from_dict,
    fit,
    sampler,
)


def test_a_fixed_time_draws_nothing_from_the_random_source() -> None:
    rng = random.Random(1)
    state = rng.getstate()

    assert Fixed(4.5).sample(rng) == 4.5
    assert rng.getstate() == state


def test_a_triangular_time_stays_between_low_and_high_with_its_mean() -> None:
    rng = random.Random(2)
    samples = [Triangular(10, 20, 60).sample(rng) for _ in range(20_000)]

    assert min(samples) >= 10
    assert max(samples) <= 60
    assert statistics.fmean(samples) == pytest.approx(30, rel=0.02)


def test_a_lognormal_from_median_and_p90_has_them() -> None:
    time = Lognormal.from_median_p90(20, 35)
    rng = random.Random(3)
    samples = sorted(time.sample(rng) for _ in range(40_000))

    assert time.median == pytest.approx(20)
    assert samples[20_000] == pytest.approx(20, rel=0.03)
    assert samples[36_000] == pytest.approx(35, rel=0.03)


def test_a_lognormal_from_mean_and_sd_has_them() -> None:
    time = Lognormal.from_mean_sd(12, 3)
    rng = random.Random(4)
    samples = [time.sample(rng) for _ in range(40_000)]

    assert time.mean == pytest.approx(12)
    assert statistics.fmean(samples) == pytest.approx(12, rel=0.02)
    assert statistics.stdev(samples) == pytest.approx(3, rel=0.05)


def test_an_empirical_time_draws_the_measured_times_alike() -> None:
    rng = random.Random(5)
    samples = [Empirical((1.0, 2.0, 9.0)).sample(rng) for _ in range(9000)]

    assert set(samples) == {1.0, 2.0, 9.0}
    assert samples.count(9.0) / 9000 == pytest.approx(1 / 3, abs=0.02)


@pytest.mark.parametrize(
    "time",
    [
        Fixed(3.0),
        Triangular(2, 4, 8),
        Triangular(2.5, 2.5, 7.25),
        Triangular(1.5, 9.0, 9.0),
        Triangular(3, 3, 3),
        Lognormal(1.0, 0.4),
        Empirical((1.0, 2.5, 7.0)),
    ],
    ids=["fixed", "triangular", "mode-low", "mode-high", "no-spread", "lognormal", "empirical"],
)
def test_a_sampler_draws_what_sample_draws_from_the_same_source(time: Duration) -> None:
    by_sample, by_sampler = random.Random(9), random.Random(9)
    draw = sampler(time, by_sampler)

    assert [draw() for _ in range(2000)] == [time.sample(by_sample) for _ in range(2000)]


def test_fit_gives_a_fixed_time_for_times_that_do_not_vary_and_drops_impossible_ones() -> None:
    assert fit([7.0, 7.0, -1.0, math.nan]) == Fixed(7.0)
    assert fit([3.0]) == Fixed(3.0)
    with pytest.raises(DurationError, match="no measured time"):
        fit([-2.0, math.inf])


def test_fit_gives_the_lognormal_of_the_logs_mean_and_deviation() -> None:
    rng = random.Random(6)
    measured = [Lognormal.from_median_p90(30, 45).sample(rng) for _ in range(5000)]

    fitted = fit(measured)

    assert isinstance(fitted, Lognormal)
    assert fitted.median == pytest.approx(30, rel=0.03)
    assert fitted.mu == pytest.approx(statistics.fmean(math.log(t) for t in measured))


def test_fit_keeps_the_measured_times_when_one_is_zero() -> None:
    assert fit([0.0, 0.5, 0.7]) == Empirical((0.0, 0.5, 0.7))


@pytest.mark.parametrize(
    "time",
    [Fixed(3), Triangular(1, 2, 4), Lognormal.from_median_p90(10, 20), Empirical((1.0, 4.0))],
)
def test_what_as_dict_writes_reads_back_as_the_same_time(time: object) -> None:
    assert duration_from_dict(time.as_dict()) == time  # type: ignore[attr-defined]


def test_a_lognormal_may_be_given_by_its_median_and_p90_or_its_mean_and_sd() -> None:
    by_percentiles = duration_from_dict({"kind": "lognormal", "median": 10, "p90": 20})
    by_moments = duration_from_dict({"kind": "lognormal", "mean": 10, "sd": 2})

    assert by_percentiles == Lognormal.from_median_p90(10, 20)
    assert by_moments == Lognormal.from_mean_sd(10, 2)


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"kind": "fixed", "seconds": -1}, "seconds must be a finite number of seconds ≥ 0"),
        ({"kind": "fixed"}, "a fixed time needs 'seconds'"),
        ({"kind": "triangular", "low": 5, "mode": 2, "high": 9}, "low ≤ mode ≤ high"),
        ({"kind": "lognormal", "median": 10, "p90": 5}, "0 < median ≤ p90"),
        ({"kind": "empirical", "samples": []}, "at least one measured time"),
        ({"kind": "fixed", "seconds": True}, "must be a number of seconds"),
        ({"kind": "normal"}, "fixed, triangular, lognormal or empirical"),
    ],
)
def test_a_time_that_makes_no_sense_is_refused_saying_why(
    data: dict[str, object], message: str
) -> None:
    with pytest.raises(DurationError, match=message):
        duration_from_dict(data)
