"""Interval arithmetic shared by the result tools: mean and two-sided 95 % Student-t
half-width over independent runs (one run per evaluation seed); for paired comparisons the
paired-t and a seeded bootstrap interval; for pooled rates the exact Clopper-Pearson interval
(with an own incomplete beta function when scipy is not there)."""
import math

# Two-sided 95 % Student-t quantiles t(0.975, df) for df = 1..30; beyond, the normal 1.96
# is within 2 % of the exact value.
_T975 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
         2.201, 2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
         2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042]


def t975(df):
    """t quantile for a two-sided 95 % interval with df degrees of freedom (df >= 1)."""
    if df < 1:
        raise ValueError(f"t975: degrees of freedom must be >= 1, got {df}")
    return _T975[df - 1] if df <= len(_T975) else 1.96


def mean_ci95(values):
    """(mean, half-width) of the 95 % interval; half-width is nan for fewer than 2 values.
    Non-finite values are refused: a run that produced no number is a missing run, not 0."""
    values = [float(v) for v in values]
    if not values:
        raise ValueError("mean_ci95: no values")
    if not all(math.isfinite(v) for v in values):
        raise ValueError(f"mean_ci95: non-finite value in {values}")
    n = len(values)
    mean = sum(values) / n
    if n < 2:
        return mean, float("nan")
    sd = math.sqrt(sum((v - mean) ** 2 for v in values) / (n - 1))
    return mean, t975(n - 1) * sd / math.sqrt(n)


def format_ci(mean, half, digits):
    """'mean ± half' with the given decimals, or 'mean' alone when half is nan."""
    if math.isfinite(half):
        return f"{mean:.{digits}f} ± {half:.{digits}f}"
    return f"{mean:.{digits}f}"


# --- Paired comparisons and pooled rates (tools/trial_results.py) ---------------------------

def t_interval(values):
    """(mean, low, high) of the two-sided 95 % Student-t interval; low = high = nan for fewer
    than 2 values. For paired differences: the paired-t interval."""
    mean, half = mean_ci95(values)
    return mean, mean - half, mean + half


def stable_seed(*parts):
    """A seed for a random generator named by its parts (the same parts: the same seed on
    every machine and run, whatever else was computed before)."""
    import zlib
    return zlib.crc32("|".join(str(p) for p in parts).encode())


def bootstrap_mean_ci(values, seed, resamples=10000, level=0.95):
    """(low, high): the percentile bootstrap interval of the mean, `resamples` resamples of
    the values with replacement drawn by numpy's PCG64 seeded with `seed`. Paired data: pass
    the per-pair differences (or ratios), so each resample keeps its pairs together."""
    import numpy as np
    v = np.asarray([float(x) for x in values], dtype=float)
    if v.size == 0:
        raise ValueError("bootstrap_mean_ci: no values")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"bootstrap_mean_ci: non-finite value in {list(values)}")
    rng = np.random.default_rng(seed)
    means = v[rng.integers(0, v.size, size=(resamples, v.size))].mean(axis=1)
    tail = 100.0 * (1.0 - level) / 2.0
    lo, hi = np.percentile(means, [tail, 100.0 - tail])
    return float(lo), float(hi)


def _betacf(a, b, x):
    """The continued fraction of the incomplete beta function (modified Lentz)."""
    tiny, eps = 1e-300, 1e-15
    qab, qap, qam = a + b, a + 1.0, a - 1.0
    c, d = 1.0, 1.0 - qab * x / qap
    d = 1.0 / (d if abs(d) > tiny else tiny)
    h = d
    for m in range(1, 100000):
        m2 = 2 * m
        aa = m * (b - m) * x / ((qam + m2) * (a + m2))
        d = 1.0 + aa * d
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = 1.0 + aa / c
        c = c if abs(c) > tiny else tiny
        h *= d * c
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))
        d = 1.0 + aa * d
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = 1.0 + aa / c
        c = c if abs(c) > tiny else tiny
        delta = d * c
        h *= delta
        if abs(delta - 1.0) < eps:
            return h
    raise ArithmeticError(f"incomplete beta: no convergence for a={a}, b={b}, x={x}")


def betainc_reg(a, b, x):
    """The regularized incomplete beta function I_x(a, b), a, b > 0, 0 <= x <= 1."""
    if not (a > 0 and b > 0):
        raise ValueError(f"betainc_reg: a = {a}, b = {b} must be > 0")
    if not 0.0 <= x <= 1.0:
        raise ValueError(f"betainc_reg: x = {x} is outside [0, 1]")
    if x in (0.0, 1.0):
        return x
    log_front = (math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b)
                 + a * math.log(x) + b * math.log1p(-x))
    if x < (a + 1.0) / (a + b + 2.0):
        return math.exp(log_front) * _betacf(a, b, x) / a
    return 1.0 - math.exp(log_front) * _betacf(b, a, 1.0 - x) / b


def beta_ppf(q, a, b):
    """The q-quantile of the Beta(a, b) distribution: bisection on betainc_reg (monotone in
    x) to below 1e-15."""
    if not 0.0 <= q <= 1.0:
        raise ValueError(f"beta_ppf: q = {q} is outside [0, 1]")
    lo, hi = 0.0, 1.0
    for _ in range(200):
        mid = (lo + hi) / 2.0
        if betainc_reg(a, b, mid) < q:
            lo = mid
        else:
            hi = mid
        if hi - lo < 1e-15:
            break
    return (lo + hi) / 2.0


def clopper_pearson(k, n, level=0.95, use_scipy=True):
    """(low, high): the exact (Clopper-Pearson) interval of a binomial proportion, k events
    in n trials, as fractions. scipy's beta quantile when it is importable (use_scipy),
    else beta_ppf above; both are exact to far below the printed digits."""
    k, n = int(k), int(n)
    if n < 1 or not 0 <= k <= n:
        raise ValueError(f"clopper_pearson: {k} of {n} is not a proportion")
    alpha = 1.0 - level
    ppf = beta_ppf
    if use_scipy:
        try:
            from scipy.stats import beta as _beta

            def ppf(q, a, b):
                return float(_beta.ppf(q, a, b))
        except ImportError:
            pass
    lo = 0.0 if k == 0 else ppf(alpha / 2.0, k, n - k + 1)
    hi = 1.0 if k == n else ppf(1.0 - alpha / 2.0, k + 1, n - k)
    return lo, hi
