"""A second implementation of the manufactured solutions of Gong (mms1d_gong, mms2d_gong) and Tran
(mms1d_tran): each benchmark's wave, the exact particle states and the exact grid velocity by
the inverse motion.
"""

from typing import Callable, NamedTuple

import numpy as np

from layout import RTOL_FIELD


# --------------------------------------------------------------------------------------------
# Second implementation of the manufactured solutions


class Wave(NamedTuple):
    """U_k = amplitude sin(k X_k) sin(omega t) in each direction, neo-Hookean (lam, mu)."""

    amplitude: float
    k: float
    omega: float
    lam: float
    mu: float
    rho0: float


def gong_wave(run):
    """Gong 2015 sec 4.5: G sin(pi X) sin(c pi t), c = sqrt(E / rho0), Lame from E and nu."""
    G, E, nu, rho0 = (run.param(k) for k in ("G", "E", "nu", "rho0"))
    c = np.sqrt(E / rho0)
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    return Wave(G, np.pi, c * np.pi, lam, mu, rho0)


def tran_wave(run):
    """Tran et al. 2019 eq 44: A sin(2 pi X / L) sin(c pi t / L), c = sqrt(E / rho0) with
    E = mu (3 lambda + 2 mu) / (lambda + mu)."""
    A, lam, mu, rho0, L = (run.param(k) for k in ("A", "lambda", "mu", "rho0", "L"))
    E = mu * (3 * lam + 2 * mu) / (lam + mu)
    c = np.sqrt(E / rho0)
    return Wave(A, 2 * np.pi / L, c * np.pi / L, lam, mu, rho0)


def gong_max_dt(run):
    a = run.attrs
    return run.param("cfl") * a["h"] * np.sqrt(run.param("rho0") / run.param("E"))


class Benchmark(NamedTuple):
    dim: int
    params: tuple  # parameters besides rho0, t_end, ppc and cells
    length: Callable  # run -> edge of the domain [0, L]^dim
    wave: Callable  # run -> Wave
    max_dt: Callable  # run -> the step the time step may not exceed


GONG_PARAMS = ("G", "E", "nu", "cfl", "courant_limit")
BENCHMARKS = {
    "mms1d_gong": Benchmark(1, GONG_PARAMS, lambda run: 1.0, gong_wave, gong_max_dt),
    "mms2d_gong": Benchmark(2, GONG_PARAMS, lambda run: 1.0, gong_wave, gong_max_dt),
    "mms1d_tran": Benchmark(
        1,
        ("A", "mu", "lambda", "L", "dt"),
        lambda run: run.param("L"),
        tran_wave,
        lambda run: run.param("dt"),
    ),
}


def sine_exact(X, t, w):
    """Exact displacement, velocity, Cauchy stress and density of the material points that
    started at X (Np, D), at times t (Nt,). Returns arrays shaped (Nt, Np, ...).

    F = diag(1 + k A cos(k X_k) sin(omega t)), J = prod F_kk, rho = rho0 / J,
    sigma = (lambda ln J I + mu (F F^T - I)) / J.
    """
    st = np.sin(w.omega * t)[:, None, None]
    ct = np.cos(w.omega * t)[:, None, None]
    sx = np.sin(w.k * X)[None]
    cx = np.cos(w.k * X)[None]
    u = w.amplitude * sx * st
    v = w.omega * w.amplitude * sx * ct
    f = 1 + w.k * w.amplitude * cx * st  # diagonal of F, (Nt, Np, D)
    j = np.prod(f, axis=-1)
    d = X.shape[1]
    sigma = np.zeros(f.shape + (d,))
    diag = (w.lam * np.log(j)[..., None] + w.mu * (f**2 - 1)) / j[..., None]
    for k in range(d):
        sigma[..., k, k] = diag[..., k]
    return u, v, sigma, w.rho0 / j


def grid_exact_velocity(x, t, t_v, w):
    """The exact velocity at times t_v (Nt,) of the material points at x (Nn, D) at times t
    (Nt,), (Nt, Nn, D): X with X + A sin(k X) sin(omega t) = x per axis found by bisection on
    [x - |b|, x + |b|] (b = A sin(omega t)), where the increasing left side brackets x, then
    omega A sin(k X) cos(omega t_v)."""
    b = (w.amplitude * np.sin(w.omega * t))[:, None, None]
    target = np.broadcast_to(x[None], (t.shape[0],) + x.shape)
    lo, hi = target - np.abs(b), target + np.abs(b)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        above = mid + b * np.sin(w.k * mid) > target
        hi = np.where(above, mid, hi)
        lo = np.where(above, lo, mid)
    X = 0.5 * (lo + hi)
    return w.omega * w.amplitude * np.sin(w.k * X) * np.cos(w.omega * t_v)[:, None, None]


def _check_pointwise(name, stored, recomputed, numerical, exact):
    finite = np.isfinite(numerical) & np.isfinite(exact)
    scale = max(np.max(np.abs(numerical[finite]), initial=0), np.max(np.abs(exact), initial=0))
    np.testing.assert_allclose(
        stored, recomputed, rtol=0, atol=RTOL_FIELD * scale + 1e-300, equal_nan=True,
        err_msg=f"/errors/{name} does not match the independently computed errors",
    )
