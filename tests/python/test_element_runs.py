"""Element-wise runs (recon_tls): the /elements group, the data and Gauss points, each element's
Taylor fit by numpy's SVD least squares, and the errors.
"""

import numpy as np
import pytest

from layout import RTOL_STORED
from sampling import FUNCTIONS, Lcg, cell_fractions


# --------------------------------------------------------------------------------------------
# Element-wise runs: a second implementation of the elements, the data, the Taylor least
# squares of each element, the Gauss points and the errors

ELEMENT_DATASETS = {
    # name: (per element, data point, Gauss point or curve sample; with a D column; integer)
    "lower": ("element", True, False),
    "upper": ("element", True, False),
    "mean": ("element", False, False),
    "element_degree": ("element", False, True),
    "data_x": ("data", True, False),
    "data_u": ("data", False, False),
    "data_element": ("data", False, True),
    "gauss_x": ("gauss", True, False),
    "gauss_weight": ("gauss", False, False),
    "gauss_element": ("gauss", False, True),
    "exact": ("gauss", False, False),
    "reconstructed": ("gauss", False, False),
    "error": ("gauss", False, False),
    "curve_x": ("curve", True, False),
    "curve_element": ("curve", False, True),
    "curve_exact": ("curve", False, False),
    "curve_reconstructed": ("curve", False, False),
    "map_x": ("map", True, False),
    "map_element": ("map", False, True),
    "map_exact": ("map", False, False),
    "map_reconstructed": ("map", False, False),
}
# Map samples per axis across a 2D domain: MAP_SAMPLES // cells per element (at least one).
MAP_SAMPLES = 60
CONSERVATION = {"tls_fixed": "fixed", "tls_fitted": "fitted"}
TLS_DEGREE = 2
SURFACES = {
    "sin_x_cos_y": lambda x, y: np.sin(x) * np.cos(y),
    "x2_plus_xy": lambda x, y: x * x + x * y,
}
# Singular values of the scaled basis at the data below this fraction of the largest count as
# zero: the kernel's criterion is sin^2 of an angle <= 1e-10, i.e. an angle of 1e-5.
RANK_SVD = 1e-5


def element_function(name):
    """u at points of shape (N, D)."""
    if name in SURFACES:
        f = SURFACES[name]
        return lambda p: f(p[:, 0], p[:, 1])
    f = FUNCTIONS[name]
    return lambda p: f(p[:, 0])


def taylor_basis(s, degree):
    """The Taylor functions of Wobbes sec 2 at scaled offsets s (N, D), (x - x_c)/dx: 1, s, then
    s^2/2 - 1/6 (each axis) and s t in 2D; shape (N, terms)."""
    d = s.shape[1]
    cols = [np.ones(len(s))]
    if degree >= 1:
        cols += [s[:, k] for k in range(d)]
    if degree >= 2:
        cols += [s[:, k] ** 2 / 2 - 1 / 6 for k in range(d)]
        if d == 2:
            cols.append(s[:, 0] * s[:, 1])
    return np.array(cols).T


def taylor_terms(d, degree):
    return [1, 1 + d, 3 if d == 1 else 6][degree]


def gauss_box(lo, hi, n):
    """n^D Gauss points (x fastest) and weights in the box [lo, hi]."""
    g, w = np.polynomial.legendre.leggauss(n)
    c, half = (lo + hi) / 2, (hi - lo) / 2
    grids = np.meshgrid(*[c[k] + half[k] * g for k in range(len(lo))], indexing="ij")
    weights = np.meshgrid(*[half[k] * w for k in range(len(lo))], indexing="ij")
    # meshgrid with ij indexing varies the last axis fastest; transpose so x varies fastest.
    x = np.stack([gr.T.ravel() for gr in grids], axis=1)
    weight = np.prod(np.stack([wt.T.ravel() for wt in weights], axis=1), axis=1)
    return x, weight


def expected_elements(run):
    """The element boxes (x fastest) and the data points of each, as the README documents."""
    p = run.values("/params")
    d = run.attrs["dim"]
    lower, upper, cells = p["lower"], p["upper"], int(p["cells"])
    h = (upper - lower) / cells
    n = [int(p["ppc"]), int(p["ppc_y"])][:d]
    rng = Lcg(int(p["seed"]))
    boxes, points = [], []
    for e in range(cells**d):
        index = [(e // cells**k) % cells for k in range(d)]
        lo = np.array([lower + i * h for i in index])
        hi = np.array([lower + (i + 1) * h for i in index])
        if d == 2 and p["spacing"] == "random":
            f = [[rng.unit() for _ in range(d)] for _ in range(n[0] * n[1])]
        else:
            axes = [cell_fractions(p["spacing"], index[k], n[k], rng) for k in range(d)]
            f = [[axes[k][(j // int(np.prod(n[:k]))) % n[k]] for k in range(d)]
                 for j in range(int(np.prod(n)))]
        boxes.append((lo, hi))
        points.append(np.array([[lower + (index[k] + fk[k]) * h for k in range(d)] for fk in f]))
    return boxes, points


def test_elements_layout(run):
    run.require_elements()
    a, g = run.attrs, run.group("/elements")
    assert a["benchmark"] == "recon_tls"
    for name in ("formula", "conservation"):
        assert isinstance(g.get(name), str), f"/elements attribute {name} is not a string"
    for name in ("degree", "gauss", "degraded"):
        assert isinstance(g.get(name), (int, np.integer)), f"/elements {name} is not an integer"
    for name in ("rms", "integral", "exact_integral", "integral_error"):
        assert isinstance(g.get(name), (float, np.floating)), f"/elements {name} is not a float"
    assert g["conservation"] == CONSERVATION[a["method"]] and g["degree"] == TLS_DEGREE
    for name in ("/particles", "/history", "/errors", "/reconstruction"):
        assert name not in run.groups, f"element-wise run with {name}"
    d = a["dim"]
    n = {}
    for name, (what, with_d, integer) in ELEMENT_DATASETS.items():
        arr = run.ds(f"/elements/{name}")
        assert isinstance(run.units[f"/elements/{name}"], str), f"{name} has no units"
        kind = np.integer if integer else np.floating
        assert np.issubdtype(arr.dtype, kind), f"/elements/{name} dtype {arr.dtype}"
        assert arr.ndim == (2 if with_d else 1), f"/elements/{name} has shape {arr.shape}"
        if with_d:
            assert arr.shape[1] == d, f"/elements/{name} has {arr.shape[1]} columns, dim {d}"
        assert n.setdefault(what, arr.shape[0]) == arr.shape[0], f"/elements/{name} length"
    coefficients = run.ds("/elements/coefficients")
    assert coefficients.shape == (n["element"], taylor_terms(d, g["degree"]))
    if run.status == "ok":
        assert n["element"] == a["cells"] ** d
        assert n["gauss"] == n["element"] * g["gauss"] ** d
        m = max(MAP_SAMPLES // a["cells"], 1) if d == 2 else 0
        assert n["map"] == n["element"] * m**d, f"{n['map']} map samples"


def test_elements_data_gauss_points_and_norms(run):
    run.require_elements()
    if run.status != "ok":
        pytest.skip("the run did not complete")
    p, g = run.values("/params"), run.group("/elements")
    u = element_function(p["function"])
    boxes, points = expected_elements(run)
    lower, upper = run.ds("/elements/lower"), run.ds("/elements/upper")
    np.testing.assert_allclose(lower, [b[0] for b in boxes], rtol=0, atol=1e-14)
    np.testing.assert_allclose(upper, [b[1] for b in boxes], rtol=0, atol=1e-14)
    data_x = run.ds("/elements/data_x")
    np.testing.assert_allclose(data_x, np.concatenate(points), rtol=0, atol=1e-14,
                               err_msg="data points differ from the documented placement")
    owner = np.concatenate([np.full(len(pts), e) for e, pts in enumerate(points)])
    np.testing.assert_array_equal(run.ds("/elements/data_element"), owner)
    np.testing.assert_allclose(run.ds("/elements/data_u"), u(data_x), rtol=0, atol=1e-14)

    xs, ws = zip(*(gauss_box(lo, hi, int(g["gauss"])) for lo, hi in boxes))
    np.testing.assert_allclose(run.ds("/elements/gauss_x"), np.concatenate(xs), rtol=0,
                               atol=1e-13, err_msg="Gauss points")
    weight = run.ds("/elements/gauss_weight")
    np.testing.assert_allclose(weight, np.concatenate(ws), rtol=1e-13, err_msg="Gauss weights")
    gx = run.ds("/elements/gauss_x")
    exact = run.ds("/elements/exact")
    np.testing.assert_allclose(exact, u(gx), rtol=0, atol=1e-14)
    uh = run.ds("/elements/reconstructed")
    e = run.ds("/elements/error")
    np.testing.assert_array_equal(e, exact - uh, err_msg="error != exact - reconstructed")
    np.testing.assert_allclose(g["rms"], np.sqrt(np.mean(e**2)), rtol=RTOL_STORED, err_msg="rms")
    integral = np.sum(weight * uh)
    np.testing.assert_allclose(g["integral"], integral, rtol=1e-13, err_msg="integral")
    # The exact integral by 20 Gauss points per axis and element: smooth u on small boxes.
    exact_integral = sum(np.sum(w * u(x)) for x, w in
                         (gauss_box(lo, hi, 20) for lo, hi in boxes))
    np.testing.assert_allclose(g["exact_integral"], exact_integral, rtol=1e-13)
    relative = abs(g["integral"] - g["exact_integral"]) / abs(g["exact_integral"])
    np.testing.assert_allclose(g["integral_error"], relative, rtol=RTOL_STORED,
                               err_msg="integral_error")


def test_element_fits_by_a_second_implementation(run):
    run.require_elements()
    if run.status != "ok":
        pytest.skip("the run did not complete")
    a, p, g = run.attrs, run.values("/params"), run.group("/elements")
    d, fixed = a["dim"], g["conservation"] == "fixed"
    u = element_function(p["function"])
    lower, upper = run.ds("/elements/lower"), run.ds("/elements/upper")
    data_x, data_u = run.ds("/elements/data_x"), run.ds("/elements/data_u")
    owner = run.ds("/elements/data_element")
    stored = run.ds("/elements/coefficients")
    degrees = run.ds("/elements/element_degree")
    means = run.ds("/elements/mean")
    first = 1 if fixed else 0
    for e in range(len(lower)):
        lo, hi = lower[e], upper[e]
        c, half = (lo + hi) / 2, (hi - lo) / 2
        x, w = gauss_box(lo, hi, 20)
        mean = np.sum(w * u(x)) / np.prod(hi - lo)
        np.testing.assert_allclose(means[e], mean, rtol=1e-13, atol=1e-15, err_msg=f"mean {e}")
        s = (data_x[owner == e] - c) / half
        values = data_u[owner == e] - (mean if fixed else 0.0)
        # The highest degree whose fitted Taylor functions are independent at the data.
        for degree in range(g["degree"], -1, -1):
            b = taylor_basis(s, degree)[:, first:]
            if b.shape[1] == 0:
                break
            sv = np.linalg.svd(b / np.linalg.norm(b, axis=0).clip(1e-300), compute_uv=False)
            if len(s) >= b.shape[1] and sv[-1] > RANK_SVD * sv[0]:
                break
        assert degrees[e] == degree, f"element {e}: degree {degrees[e]}, expected {degree}"
        coefficients = np.zeros(stored.shape[1])
        if fixed:
            coefficients[0] = mean
        if b.shape[1]:
            solution, *_ = np.linalg.lstsq(b, values, rcond=None)
            coefficients[first:first + len(solution)] = solution
        scale = max(np.max(np.abs(data_u[owner == e])), 1.0)
        np.testing.assert_allclose(stored[e], coefficients, rtol=0, atol=1e-9 * scale,
                                   err_msg=f"coefficients of element {e}")
    assert g["degraded"] == np.count_nonzero(degrees < g["degree"])

    # u^h at the Gauss points and the plot and map samples from the stored coefficients.
    for where, element, values in (("gauss_x", "gauss_element", "reconstructed"),
                                   ("curve_x", "curve_element", "curve_reconstructed"),
                                   ("map_x", "map_element", "map_reconstructed")):
        x, owners = run.ds(f"/elements/{where}"), run.ds(f"/elements/{element}")
        if len(x) == 0:
            continue
        c, half = (lower[owners] + upper[owners]) / 2, (upper[owners] - lower[owners]) / 2
        psi = taylor_basis((x - c) / half, g["degree"])
        expected = np.sum(psi * stored[owners], axis=1)
        got = run.ds(f"/elements/{values}")
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12 * max(1.0, np.max(np.abs(expected))),
                                   err_msg=f"u^h at {where}")
    for where, values in (("curve_x", "curve_exact"), ("map_x", "map_exact")):
        x = run.ds(f"/elements/{where}")
        np.testing.assert_allclose(run.ds(f"/elements/{values}"), u(x), rtol=0, atol=1e-14)
    if d == 2:
        # The map: the cell centres of an m x m lattice in each element, x fastest.
        m = max(MAP_SAMPLES // a["cells"], 1)
        t = (np.arange(m) + 0.5) / m
        tx, ty = np.meshgrid(t, t)
        f = np.stack([tx.ravel(), ty.ravel()], axis=1)
        expected = np.concatenate([lower[e] + f * (upper[e] - lower[e]) for e in range(len(lower))])
        np.testing.assert_allclose(run.ds("/elements/map_x"), expected, rtol=0, atol=1e-13,
                                   err_msg="map samples")
        np.testing.assert_array_equal(run.ds("/elements/map_element"),
                                      np.repeat(np.arange(len(lower)), m * m))
