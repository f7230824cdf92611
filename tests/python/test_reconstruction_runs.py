"""Reconstruction runs (recon1d_nodes, recon1d_basis): the /reconstruction group, the data points,
u^h by an independent least-squares fit, the norms and the orthogonal basis.
"""

import numpy as np
import pytest

from layout import RTOL_STORED
from sampling import FUNCTIONS, Lcg, RECONSTRUCTION, cell_fractions


# --------------------------------------------------------------------------------------------
# Reconstruction runs: a second implementation of the data, the fit, the norms and the basis

RECONSTRUCTION_DATASETS = (
    "x", "exact", "reconstructed", "error", "data_x", "data_u", "curve_x", "curve_u",
)
BASIS_DATASETS = ("coefficients", "norms", "kept", "data_weight", "data_p", "curve_p")
# The same criterion as the fits: a polynomial is dropped when <p, p> <= RANK * <q, q>.
RANK = 1e-10
DEGREES = {"shepard": 0, "mls_linear": 1, "mls_quadratic": 2, "imls_linear": 1,
           "imls_quadratic": 2}



def weight(name, r):
    """The B-spline weights of order 1, 2, 3 at r >= 0 (in units of the support length)."""
    r = np.abs(r)
    if name == "hat":
        return np.maximum(1.0 - r, 0.0)
    if name == "quadratic":
        return np.where(r < 0.5, 0.75 - r**2, np.where(r < 1.5, 0.5 * (1.5 - r) ** 2, 0.0))
    if name == "cubic":
        return np.where(r < 1.0, 2 / 3 - r**2 + 0.5 * r**3, np.where(r < 2.0, (2 - r) ** 3 / 6, 0.0))
    raise AssertionError(f"unknown weight {name}")


def orthogonal_basis(s, w, degree):
    """Gram-Schmidt on the monomials s^j, j <= degree, as value vectors at the points with the
    inner product <f, g> = sum_p w_p f_p g_p. Returns the coefficient matrix C (p_i = sum_j
    C_ij s^j), the norms <p_i, p_i> and which are kept."""
    m = degree + 1
    q = np.array([s**j for j in range(m)])
    coeffs = np.zeros((m, m))
    norms = np.zeros(m)
    kept = np.zeros(m, dtype=bool)
    for i in range(m):
        c = np.zeros(m)
        c[i] = 1.0
        for k in range(i):
            if kept[k]:
                pk = coeffs[k] @ q
                c -= (np.sum(w * q[i] * pk) / norms[k]) * coeffs[k]
        p = c @ q
        coeffs[i] = c
        norms[i] = np.sum(w * p * p)
        kept[i] = norms[i] > RANK * np.sum(w * q[i] ** 2)
    return coeffs, norms, kept


def reconstruct_at(xe, data_x, data_u, h, weight_name, scale, degree):
    """u^h(xe) by weighted least squares with the polynomials the data support (equal to MLS
    where the moments are regular); NaN without data in reach."""
    s = (data_x - xe) / h
    w = weight(weight_name, s / scale)
    inside = w > 0
    if not inside.any():
        return np.nan
    s, w, u = s[inside], w[inside], data_u[inside]
    coeffs, norms, kept = orthogonal_basis(s, w, degree)
    q = np.array([s**j for j in range(degree + 1)])
    value = 0.0
    for i in np.flatnonzero(kept):
        p = coeffs[i] @ q
        value += coeffs[i][0] * np.sum(w * p * u) / norms[i]  # p_i(xe) = C_i0 (s = 0 there)
    return value






def expected_points(run):
    p = run.values("/params")
    if run.attrs["benchmark"] == "recon1d_basis":
        return np.asarray(p["points"], dtype=float)
    lower, upper, cells, ppc = p["lower"], p["upper"], int(p["cells"]), int(p["ppc"])
    h = (upper - lower) / cells
    rng = Lcg(int(p["seed"]))
    fractions = [cell_fractions(p["spacing"], c, ppc, rng) for c in range(cells)]
    return np.array([lower + (c + f) * h for c in range(cells) for f in fractions[c]])


def test_reconstruction_layout(run):
    run.require_reconstruction()
    a = run.attrs
    assert a["benchmark"] in RECONSTRUCTION
    g = run.group("/reconstruction")
    for name in ("formula", "weight", "solver"):
        assert isinstance(g.get(name), str), f"/reconstruction attribute {name} is not a string"
    for name in ("degree", "fits", "rank_deficient", "uncovered"):
        assert isinstance(g.get(name), (int, np.integer)), f"/reconstruction {name} not an integer"
    for name in ("scale", "l2", "max"):
        assert isinstance(g.get(name), (float, np.floating)), f"/reconstruction {name} not a float"
    assert g["solver"] in ("mls", "imls") and g["degree"] == DEGREES[a["method"]]
    for name in ("/particles", "/history", "/errors"):
        assert name not in run.groups, f"reconstruction run with {name}"
    sizes = {}
    for name in RECONSTRUCTION_DATASETS:
        arr = run.ds(f"/reconstruction/{name}")
        assert arr.ndim == 1 and arr.dtype == np.float64, f"/reconstruction/{name}: {arr.dtype}"
        assert isinstance(run.units[f"/reconstruction/{name}"], str), f"{name} has no units"
        sizes[name] = arr.shape[0]
    assert sizes["x"] == sizes["exact"] == sizes["reconstructed"] == sizes["error"]
    assert sizes["data_x"] == sizes["data_u"] and sizes["curve_x"] == sizes["curve_u"]
    if run.status == "ok":
        assert sizes["x"] == a["cells"] + 1, "one evaluation point per grid node"
    has_basis = "/reconstruction/basis" in run.groups
    if a["benchmark"] == "recon1d_nodes":
        assert not has_basis, "recon1d_nodes records no orthogonal basis"
    elif run.status == "ok":
        assert has_basis, "recon1d_basis records the orthogonal basis"
    if has_basis:
        m = DEGREES[a["method"]] + 1
        np_, nc = sizes["data_x"], sizes["curve_x"]
        shapes = {"coefficients": (m, m), "norms": (m,), "kept": (m,), "data_weight": (np_,),
                  "data_p": (m, np_), "curve_p": (m, nc)}
        for name, shape in shapes.items():
            arr = run.ds(f"/reconstruction/basis/{name}")
            assert arr.shape == shape, f"basis/{name} has shape {arr.shape}, expected {shape}"
            kind = np.integer if name == "kept" else np.floating
            assert np.issubdtype(arr.dtype, kind), f"basis/{name} dtype {arr.dtype}"
            assert isinstance(run.units[f"/reconstruction/basis/{name}"], str)


def test_reconstruction_data_and_norms(run):
    run.require_reconstruction()
    if run.status == "failed" and run.ds("/reconstruction/x").size == 0:
        pytest.skip("failed run without a grid")
    a, p, g = run.attrs, run.values("/params"), run.group("/reconstruction")
    f = FUNCTIONS[p["function"]]
    x = run.ds("/reconstruction/x")
    lower, upper, h = p["lower"], p["upper"], a["h"]
    np.testing.assert_allclose(h, (upper - lower) / a["cells"], rtol=1e-15)
    np.testing.assert_allclose(x, lower + h * np.arange(a["cells"] + 1), rtol=0, atol=1e-14)
    data_x = run.ds("/reconstruction/data_x")
    np.testing.assert_allclose(data_x, expected_points(run), rtol=0, atol=1e-14,
                               err_msg="data points differ from the documented placement")
    np.testing.assert_allclose(run.ds("/reconstruction/data_u"), f(data_x), rtol=0, atol=1e-14)
    np.testing.assert_allclose(run.ds("/reconstruction/exact"), f(x), rtol=0, atol=1e-14)
    curve_x = run.ds("/reconstruction/curve_x")
    assert curve_x[0] == lower and abs(curve_x[-1] - upper) < 1e-14
    np.testing.assert_allclose(run.ds("/reconstruction/curve_u"), f(curve_x), rtol=0, atol=1e-14)

    uh = run.ds("/reconstruction/reconstructed")
    e = run.ds("/reconstruction/error")
    np.testing.assert_array_equal(e, run.ds("/reconstruction/exact") - uh,
                                  err_msg="error != exact - reconstructed")
    assert g["uncovered"] == np.count_nonzero(np.isnan(uh)) or run.status == "failed"
    l2 = np.sqrt(np.sum(h * e**2))
    mx = np.max(np.abs(e)) if e.size else np.nan
    np.testing.assert_allclose(g["l2"], l2, rtol=RTOL_STORED, equal_nan=True, err_msg="l2")
    np.testing.assert_allclose(g["max"], mx, rtol=RTOL_STORED, equal_nan=True, err_msg="max")


def test_reconstruction_by_a_second_implementation(run):
    run.require_reconstruction()
    if run.status != "ok":
        pytest.skip("the fit did not complete")
    a, g = run.attrs, run.group("/reconstruction")
    data_x = run.ds("/reconstruction/data_x")
    data_u = run.ds("/reconstruction/data_u")
    x = run.ds("/reconstruction/x")
    expected = np.array([
        reconstruct_at(xe, data_x, data_u, a["h"], g["weight"], g["scale"], g["degree"])
        for xe in x
    ])
    scale = max(np.max(np.abs(data_u)), 1.0)
    np.testing.assert_allclose(run.ds("/reconstruction/reconstructed"), expected, rtol=0,
                               atol=1e-9 * scale, equal_nan=True,
                               err_msg="u^h differs from an independent weighted least squares")


def test_orthogonal_basis(run):
    run.require_reconstruction()
    if "/reconstruction/basis" not in run.groups:
        pytest.skip("no orthogonal basis in this run")
    a, g = run.attrs, run.group("/reconstruction")
    centre = run.group("/reconstruction/basis")["centre"]
    data_x = run.ds("/reconstruction/data_x")
    s = (data_x - centre) / a["h"]
    w = weight(g["weight"], s / g["scale"])
    np.testing.assert_allclose(run.ds("/reconstruction/basis/data_weight"), w, rtol=1e-14)
    coeffs, norms, kept = orthogonal_basis(s, w, g["degree"])
    stored = run.ds("/reconstruction/basis/coefficients")
    np.testing.assert_allclose(stored, coeffs, rtol=0, atol=1e-9, err_msg="coefficients")
    np.testing.assert_array_equal(run.ds("/reconstruction/basis/kept"), kept.astype(int))
    stored_norms = run.ds("/reconstruction/basis/norms")
    np.testing.assert_allclose(stored_norms, norms, rtol=1e-9, atol=1e-14 * np.max(norms))
    # The stored samples are the stored polynomials; kept ones are orthogonal at the data.
    q = np.array([s**j for j in range(len(norms))])
    data_p = run.ds("/reconstruction/basis/data_p")
    np.testing.assert_allclose(data_p, stored @ q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.sum(w * data_p**2, axis=1), stored_norms, rtol=1e-9,
                               atol=1e-14 * np.max(norms))
    for i in np.flatnonzero(kept):
        for j in np.flatnonzero(kept):
            if i < j:
                inner = np.sum(w * data_p[i] * data_p[j])
                assert abs(inner) < 1e-10 * np.sqrt(norms[i] * norms[j]), f"<p{i},p{j}> = {inner}"
    sc = (run.ds("/reconstruction/curve_x") - centre) / a["h"]
    qc = np.array([sc**j for j in range(len(norms))])
    np.testing.assert_allclose(run.ds("/reconstruction/basis/curve_p"), stored @ qc, rtol=0,
                               atol=1e-12)
