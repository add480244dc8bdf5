"""White noise plus a first-order Gauss-Markov bias at irregular times (the thesis's error model).

docs/reference.md section 4 (thesis section 2.5, eq. 2.1-2.3): a measured quantity is
``x_m = x + b + w_m`` with white noise ``w_m ~ N(0, sigma_w^2)`` and a bias
``db/dt = -b / T_b + w_b``. Discretised exactly between two times ``dt`` apart::

    b[k] = exp(-dt/T_b) b[k-1] + sqrt(q (1 - exp(-2 dt/T_b)) T_b / 2) n[k],   n ~ N(0, 1)

The configuration's "bias variance" ``sigma_b^2`` is read as the bias's *stationary* variance,
``sigma_b^2 = q T_b / 2`` (so ``q = 2 sigma_b^2 / T_b``); the bias starts in its stationary
distribution, so its variance is ``sigma_b^2`` at every time and its autocorrelation
``exp(-|dt| / T_b)``.

The recursion has a coefficient per step (the times are irregular); it is solved for all steps
at once by a parallel prefix scan of the affine maps ``x -> a x + c`` (``log2 n`` numpy passes).
"""

from __future__ import annotations

import numpy as np

__all__ = ["affine_scan", "gauss_markov", "white_plus_bias"]


def affine_scan(a: np.ndarray, c: np.ndarray, x0: float = 0.0) -> np.ndarray:
    """Solve ``x[k] = a[k] x[k-1] + c[k]`` (with ``x[-1] = x0``) for every k at once.

    Parameters
    ----------
    a, c : (n,) float
        Coefficients; ``|a| <= 1`` keeps the scan numerically stable.
    x0 : float

    Returns
    -------
    (n,) float64
    """
    a = np.asarray(a, dtype=float).copy()
    c = np.asarray(c, dtype=float).copy()
    if a.size == 0:
        return c
    c[0] += a[0] * x0
    step = 1
    while step < a.size:  # Hillis-Steele: compose each map with the one `step` before it
        c[step:] = c[step:] + a[step:] * c[:-step]
        a[step:] = a[step:] * a[:-step]
        step *= 2
    return c


def gauss_markov(rng: np.random.Generator, times_s: np.ndarray, sd: float, tau_s: float) -> np.ndarray:
    """Stationary first-order Gauss-Markov process sampled at increasing times.

    Parameters
    ----------
    rng : numpy.random.Generator
    times_s : (n,) float
        Increasing sample times, s.
    sd : float
        Stationary standard deviation.
    tau_s : float
        Time constant, s.

    Returns
    -------
    (n,) float64
    """
    t = np.asarray(times_s, dtype=float)
    n = rng.standard_normal(t.size + 1)
    if t.size == 0 or sd == 0.0:
        return np.zeros(t.size)
    a = np.exp(-np.diff(t, prepend=t[0]) / tau_s)
    c = sd * np.sqrt(1.0 - a * a) * n[1:]
    # the first sample is a stationary draw, the rest follow the exact recursion
    a[0], c[0] = 0.0, sd * n[0]
    return affine_scan(a, c)


def white_plus_bias(rng: np.random.Generator, times_s: np.ndarray, white_sd: float, bias_sd: float,
                    tau_s: float) -> np.ndarray:
    """Errors ``b + w`` of the thesis's model at the given times (one named stream per quantity).

    Parameters
    ----------
    rng : numpy.random.Generator
    times_s : (n,) float
    white_sd, bias_sd : float
        Standard deviations of the white noise and of the (stationary) bias.
    tau_s : float
        Bias time constant, s.

    Returns
    -------
    (n,) float64
    """
    bias = gauss_markov(rng, times_s, bias_sd, tau_s)
    return bias + white_sd * rng.standard_normal(np.asarray(times_s).size)
