"""Interval arithmetic shared by the result tools: mean and two-sided 95 % Student-t
half-width over independent runs (one run per evaluation seed)."""
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
