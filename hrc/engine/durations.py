"""How long a task takes, as a distribution the prediction samples (prediction.py).

Four kinds, each a frozen dataclass with `sample(rng)`, `mean` and `as_dict()`:

- `Fixed(seconds)`: always the same; draws nothing from the random source, so
  fixing one task's time leaves every other task's samples as they were.
- `Triangular(low, mode, high)`: an engineer's guess ("usually 20 s, between
  15 and 40").
- `Lognormal(mu, sigma)`: the log of the time is normal with mean `mu` and
  standard deviation `sigma`. Positive and right-skewed like measured task
  times. Build it from what is known: `from_median_p90(median, p90)` (an
  engineer's two figures) or `from_mean_sd(mean, sd)` (a sample's moments).
- `Empirical(samples)`: draws one of the measured times, each as likely.

`fit(samples)` turns measured times into one of them (the analytics side's
entry); `duration_from_dict` reads what `as_dict` writes (the API's JSON);
`sampler(duration, rng)` is `sample` bound to a random source.
"""

from __future__ import annotations

import functools
import math
import random
import statistics
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any, Final

STANDARD_NORMAL: Final = statistics.NormalDist()
# The standard normal's 90th percentile: p90 = median × exp(Z90 × sigma).
Z90: Final = STANDARD_NORMAL.inv_cdf(0.9)
# The least uniform draw a quantile is taken of (random() may give 0, which has none).
TINY: Final = 1e-300
_quantile = STANDARD_NORMAL.inv_cdf


class DurationError(ValueError):
    """A distribution whose parameters make no sense (negative times, low above high)."""


@dataclass(frozen=True)
class Fixed:
    seconds: float

    def __post_init__(self) -> None:
        _check_time("seconds", self.seconds)

    def sample(self, rng: random.Random) -> float:
        return self.seconds

    @property
    def mean(self) -> float:
        return self.seconds

    def as_dict(self) -> dict[str, Any]:
        return {"kind": "fixed", "seconds": self.seconds}


@dataclass(frozen=True)
class Triangular:
    low: float
    mode: float
    high: float

    def __post_init__(self) -> None:
        for name in ("low", "mode", "high"):
            _check_time(name, getattr(self, name))
        if not self.low <= self.mode <= self.high:
            raise DurationError(
                f"a triangular time needs low ≤ mode ≤ high, not {self.low}, {self.mode}, "
                f"{self.high}."
            )

    def sample(self, rng: random.Random) -> float:
        return rng.triangular(self.low, self.high, self.mode)

    @property
    def mean(self) -> float:
        return (self.low + self.mode + self.high) / 3

    def as_dict(self) -> dict[str, Any]:
        return {"kind": "triangular", "low": self.low, "mode": self.mode, "high": self.high}


@dataclass(frozen=True)
class Lognormal:
    mu: float
    """The mean of the log of the time (log seconds); exp(mu) is the median."""
    sigma: float
    """The standard deviation of the log of the time; 0 is a fixed time."""

    def __post_init__(self) -> None:
        if not (math.isfinite(self.mu) and math.isfinite(self.sigma)) or self.sigma < 0:
            raise DurationError(f"a lognormal time needs a finite mu and sigma ≥ 0, not {self.sigma}.")  # fmt: skip

    @classmethod
    def from_median_p90(cls, median: float, p90: float) -> Lognormal:
        """Half the cases take less than `median` seconds, nine in ten less than `p90`."""
        if not 0 < median <= p90:
            raise DurationError(f"a lognormal time needs 0 < median ≤ p90, not {median}, {p90}.")
        return cls(math.log(median), math.log(p90 / median) / Z90)

    @classmethod
    def from_mean_sd(cls, mean: float, sd: float) -> Lognormal:
        """The lognormal with this mean and standard deviation (seconds)."""
        if mean <= 0 or sd < 0:
            raise DurationError(f"a lognormal time needs mean > 0 and sd ≥ 0, not {mean}, {sd}.")
        variance = math.log(1 + (sd / mean) ** 2)
        return cls(math.log(mean) - variance / 2, math.sqrt(variance))

    def sample(self, rng: random.Random) -> float:
        """exp(mu + sigma × z), z the standard normal quantile of one uniform draw: one draw
        per sample, so that a run's draws follow its events one for one."""
        return math.exp(self.mu + self.sigma * _quantile(rng.random() or TINY))

    @property
    def median(self) -> float:
        return math.exp(self.mu)

    @property
    def mean(self) -> float:
        return math.exp(self.mu + self.sigma**2 / 2)

    def as_dict(self) -> dict[str, Any]:
        return {
            "kind": "lognormal",
            "mu": self.mu,
            "sigma": self.sigma,
            "median": self.median,
            "mean": self.mean,
        }


@dataclass(frozen=True)
class Empirical:
    samples: tuple[float, ...]

    def __post_init__(self) -> None:
        if not self.samples:
            raise DurationError("an empirical time needs at least one measured time.")
        for value in self.samples:
            _check_time("a measured time", value)

    def sample(self, rng: random.Random) -> float:
        return self.samples[int(rng.random() * len(self.samples))]

    @property
    def mean(self) -> float:
        return statistics.fmean(self.samples)

    def as_dict(self) -> dict[str, Any]:
        return {"kind": "empirical", "samples": list(self.samples)}


Duration = Fixed | Triangular | Lognormal | Empirical


def sampler(duration: Duration, rng: random.Random) -> Callable[[], float]:
    """`duration.sample` bound to `rng`, for a simulation's many draws: the same draws, a
    triangular's without the call in between."""
    if isinstance(duration, Triangular) and duration.high > duration.low:
        return _triangular(duration.low, duration.mode, duration.high, rng.random)
    return functools.partial(duration.sample, rng)


def _triangular(
    low: float, mode: float, high: float, uniform: Callable[[], float]
) -> Callable[[], float]:
    """random.triangular(low, high, mode) with what depends only on the parameters worked out
    once: the same arithmetic on the same draw, so the same times."""
    below = (mode - low) / (high - low)  # the share of the draws that fall below the mode
    above = 1.0 - below
    rise, fall = high - low, low - high
    sqrt = math.sqrt

    def draw() -> float:
        u = uniform()
        if u > below:
            return high + fall * sqrt((1.0 - u) * above)
        return low + rise * sqrt(u * below)

    return draw


def fit(samples: Iterable[float]) -> Duration:
    """A distribution for measured times (seconds; negative and non-finite ones left out):
    `Fixed` when they do not vary, `Lognormal` with the mean and standard deviation of their
    logs (the maximum-likelihood fit) when all are positive, else `Empirical` (a zero, such
    as a display call's, has no log).

    Raises DurationError when no time is left."""
    values = [float(v) for v in samples if math.isfinite(v) and v >= 0]
    if not values:
        raise DurationError("there is no measured time to fit.")
    if len(values) == 1 or min(values) == max(values):
        return Fixed(statistics.fmean(values))
    if min(values) == 0:
        return Empirical(tuple(values))
    logs = [math.log(v) for v in values]
    return Lognormal(statistics.fmean(logs), statistics.stdev(logs))


def duration_from_dict(data: Mapping[str, Any]) -> Duration:
    """A distribution from what `as_dict` writes; a lognormal may be given by `mu` and `sigma`,
    `median` and `p90`, or `mean` and `sd`. Raises DurationError saying what is wrong."""
    kind = data.get("kind")
    try:
        if kind == "fixed":
            return Fixed(_number(data, "seconds"))
        if kind == "triangular":
            return Triangular(_number(data, "low"), _number(data, "mode"), _number(data, "high"))
        if kind == "lognormal":
            return _lognormal(data)
        if kind == "empirical":
            samples = data.get("samples")
            if not isinstance(samples, list):
                raise DurationError("an empirical time needs 'samples', a list of seconds.")
            return Empirical(tuple(_as_number("a sample", v) for v in samples))
    except KeyError as missing:
        raise DurationError(f"a {kind} time needs {missing.args[0]!r}.") from None
    raise DurationError(
        f"a time's 'kind' is fixed, triangular, lognormal or empirical, not {kind!r}."
    )


def _lognormal(data: Mapping[str, Any]) -> Lognormal:
    if "mu" in data or "sigma" in data:
        return Lognormal(_number(data, "mu"), _number(data, "sigma"))
    if "median" in data and "p90" in data:
        return Lognormal.from_median_p90(_number(data, "median"), _number(data, "p90"))
    return Lognormal.from_mean_sd(_number(data, "mean"), _number(data, "sd"))


def _number(data: Mapping[str, Any], key: str) -> float:
    return _as_number(repr(key), data[key])


def _as_number(what: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise DurationError(f"{what} must be a number of seconds, not {value!r}.")
    return float(value)


def _check_time(name: str, value: float) -> None:
    if not math.isfinite(value) or value < 0:
        raise DurationError(f"{name} must be a finite number of seconds ≥ 0, not {value!r}.")
