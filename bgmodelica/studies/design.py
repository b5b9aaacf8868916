"""The design of a study: grid axes (``"start:stop:n"``, ``"start:stop:n:log"``, lists),
distributions (``"normal(3,0.1)"``, ``"+-5%"``, scipy.stats objects) and the matrix of
parameter values they give, random or Latin hypercube (:func:`design`)."""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ..errors import OptionError

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def parse_grid(name: str, spec: Any) -> np.ndarray:
    """Values of one grid axis: a sequence of numbers, ``"start:stop:n"`` (n points, linear),
    ``"start:stop:n:log"`` (logarithmic) or ``"v1,v2,..."``."""
    if isinstance(spec, str):
        text = spec.strip()
        parts = text.split(":")
        try:
            if len(parts) in (3, 4):
                a, b, n = float(parts[0]), float(parts[1]), parts[2]
                if not n.strip().isdigit() or int(n) < 1:
                    raise OptionError(f"grid {name}: the number of points in {text!r} must be a "
                                      "positive integer")
                n = int(n)
                if len(parts) == 4:
                    if parts[3].strip() != "log":
                        raise OptionError(f"grid {name}: {text!r}: the fourth field may only "
                                          "be 'log'")
                    if a <= 0 or b <= 0:
                        raise OptionError(f"grid {name}: a logarithmic range needs positive "
                                          f"ends, got {text!r}")
                    values = np.geomspace(a, b, n)
                else:
                    values = np.linspace(a, b, n)
            elif len(parts) == 1:
                values = np.array([float(v) for v in text.split(",") if v.strip()])
            else:
                raise ValueError
        except ValueError:
            raise OptionError(f"grid {name}: {spec!r} is not 'start:stop:n', "
                              "'start:stop:n:log' or 'v1,v2,...'") from None
    else:
        try:
            values = np.asarray(spec, dtype=float).ravel()
        except (TypeError, ValueError):
            raise OptionError(f"grid {name}: {spec!r} is not a sequence of numbers") from None
    if values.size == 0:
        raise OptionError(f"grid {name}: no values")
    if not np.all(np.isfinite(values)):
        raise OptionError(f"grid {name}: values must be finite, got {spec!r}")
    return values


def parse_distribution(name: str, spec: Any, default: Callable[[], float]):
    """A frozen scipy.stats distribution from ``spec``:

    ``"normal(mean, std)"``, ``"uniform(low, high)"``, ``"lognormal(mu, sigma)"`` (of the
    logarithm), ``"triangular(low, mode, high)"``, ``"+-5%"`` (uniform within 5 % of the
    model's value, ``default()``), ``"+-0.1"`` (uniform within 0.1 of it); a tuple
    ``("normal", 3, 0.1)``; or any frozen scipy.stats distribution (``rvs``/``ppf``)."""
    from scipy import stats

    if hasattr(spec, "rvs") and hasattr(spec, "ppf"):
        return spec
    if isinstance(spec, (tuple, list)) and spec and isinstance(spec[0], str):
        kind, args = spec[0], [float(a) for a in spec[1:]]
        text = f"{kind}({', '.join(map(str, args))})"
    elif isinstance(spec, str):
        text = spec.strip().replace(" ", "")
        m = re.fullmatch(r"(?:\+-|±|pm)(" + _NUM + r")(%?)", text)
        if m:
            width, pct = float(m.group(1)), bool(m.group(2))
            if width < 0:
                raise OptionError(f"sample {name}: {spec!r}: the width must be positive")
            center = default()
            half = abs(center) * width / 100.0 if pct else width
            return stats.uniform(center - half, 2 * half)
        m = re.fullmatch(r"([a-z_]+)\(([^()]*)\)", text)
        if not m:
            raise OptionError(f"sample {name}: {spec!r} is not a distribution such as "
                              "normal(3,0.1), uniform(0.9,1.1), lognormal(0,0.1), "
                              "triangular(0,1,2) or +-5%")
        kind = m.group(1)
        try:
            args = [float(a) for a in m.group(2).split(",") if a]
        except ValueError:
            raise OptionError(f"sample {name}: {spec!r}: the arguments must be numbers") from None
    else:
        raise OptionError(f"sample {name}: {spec!r} is not a distribution")
    n_args = {"normal": 2, "uniform": 2, "lognormal": 2, "triangular": 3}
    if kind not in n_args:
        raise OptionError(f"sample {name}: unknown distribution {kind!r} (normal, uniform, "
                          "lognormal, triangular, +-P%)")
    if len(args) != n_args[kind] or not all(math.isfinite(a) for a in args):
        raise OptionError(f"sample {name}: {kind} takes {n_args[kind]} finite numbers, got "
                          f"{text!r}")
    if kind == "normal":
        if args[1] < 0:
            raise OptionError(f"sample {name}: the standard deviation in {text!r} is negative")
        return stats.norm(args[0], args[1])
    if kind == "uniform":
        if args[1] < args[0]:
            raise OptionError(f"sample {name}: uniform(low, high) needs low <= high: {text!r}")
        return stats.uniform(args[0], args[1] - args[0])
    if kind == "lognormal":
        if args[1] < 0:
            raise OptionError(f"sample {name}: the sigma in {text!r} is negative")
        return stats.lognorm(s=args[1], scale=math.exp(args[0]))
    lo, mode, hi = args
    if not lo <= mode <= hi or hi == lo:
        raise OptionError(f"sample {name}: triangular(low, mode, high) needs low <= mode <= "
                          f"high and low < high: {text!r}")
    return stats.triang((mode - lo) / (hi - lo), loc=lo, scale=hi - lo)


def design(grid: Mapping[str, Any] | None, samples: int | None,
           distributions: Mapping[str, Any] | None, seed: int | None,
           default: Callable[[str], float], sampling: str = "random"
           ) -> tuple[list[str], np.ndarray]:
    """Parameter names and the matrix of values (runs x names): the Cartesian product of the
    grid axes, each point combined with ``samples`` draws of ``distributions`` (random or
    Latin hypercube, reproducible with ``seed``)."""
    grid = dict(grid or {})
    distributions = dict(distributions or {})
    if distributions and samples is None:
        raise OptionError("distributions given without the number of samples (samples=N, --n)")
    if samples is not None:
        if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) \
                or samples < 1:
            raise OptionError(f"samples (--n) must be a positive integer, got {samples!r}")
        if not distributions:
            raise OptionError("samples given without distributions (distributions={...}, "
                              "--sample NAME=DIST)")
    if not grid and not distributions:
        raise OptionError("nothing to sweep: give a grid (--grid NAME=start:stop:n) and/or "
                          "distributions with a number of samples (--sample NAME=DIST --n N)")
    both = set(grid) & set(distributions)
    if both:
        raise OptionError(f"{sorted(both)[0]!r} is both on the grid and sampled")
    if sampling not in ("random", "lhs"):
        raise OptionError(f"sampling must be 'random' or 'lhs', got {sampling!r}")
    axes = [parse_grid(n, s) for n, s in grid.items()]
    points = np.array(list(itertools.product(*axes)), dtype=float).reshape(-1, len(axes)) \
        if axes else np.zeros((1, 0))
    names = list(grid)
    if distributions:
        dists = [parse_distribution(n, s, lambda n=n: default(n))
                 for n, s in distributions.items()]
        rng = np.random.default_rng(seed)
        n_total = points.shape[0] * int(samples)
        if sampling == "lhs":
            from scipy.stats import qmc

            u = qmc.LatinHypercube(d=len(dists), seed=rng).random(n_total)
            draws = np.column_stack([d.ppf(u[:, k]) for k, d in enumerate(dists)])
        else:
            draws = np.column_stack([d.rvs(size=n_total, random_state=rng) for d in dists])
        points = np.repeat(points, int(samples), axis=0)
        points = np.hstack([points, draws])
        names += list(distributions)
    if not np.all(np.isfinite(points)):
        raise OptionError("the sampled parameter values are not all finite")
    return names, points
