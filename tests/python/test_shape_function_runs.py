"""Shape-function runs (shape_functions): the lattice, the recorded nodes, N and grad N by a
second implementation of the hat and the LME basis, and the consistency errors.
"""

import numpy as np
import pytest

from catalog import METHODS


# --------------------------------------------------------------------------------------------
# Shape-function runs: the lattice, the recorded nodes, and N_a and grad N_a by a second
# implementation of the hat and of the local maximum-entropy basis.

SHAPE_FIELDS = ("partition", "moment", "gradient", "gradient_moment")
SHAPE_BASES = tuple(m["name"] for m in METHODS["shape_functions"])
# The bases this module evaluates a second time.
REIMPLEMENTED_BASES = ("lme", "linear")
# Recorded neighbours of the centre node on each side along x.
SHAPE_NEIGHBOURS = 2
# Newton's residual tolerance in units of h (the kernel's RESIDUAL_TOLERANCE).
LME_RESIDUAL = 1e-12


def shape_lattice(run):
    """The evaluation points: `points` per cell and axis on [0, cells], x fastest."""
    p = run.values("/params")
    cells, per_cell, d = int(p["cells"]), int(p["points"]), int(p["dim"])
    axis = np.arange(cells * per_cell + 1) / per_cell
    grids = np.meshgrid(*([axis] * d), indexing="ij")
    return np.stack([g.ravel(order="F") for g in grids], axis=1), cells


def grid_nodes(cells, d):
    """The grid nodes, x fastest."""
    axis = np.arange(cells + 1, dtype=float)
    grids = np.meshgrid(*([axis] * d), indexing="ij")
    return np.stack([g.ravel(order="F") for g in grids], axis=1)


def hat(x, nodes):
    """N_a(x) and grad N_a(x) of the tensor-product hat on unit cells."""
    t = 1.0 - np.abs(x - nodes)
    inside = np.all(t > 0, axis=1)
    t = np.where(inside[:, None], t, 0.0)
    n = np.prod(t, axis=1)
    sign = -np.sign(x - nodes)
    grad = np.stack([sign[:, k] * np.prod(np.delete(t, k, axis=1), axis=1)
                     for k in range(nodes.shape[1])], axis=1)
    return n, grad * inside[:, None]


def lme(x, nodes, gamma, tolerance, cells):
    """N_a(x) and grad N_a(x) of the LME basis by a damped Newton solve for the multiplier;
    on a face the LME of the face's nodes, whose gradient normal to the face is left NaN (the
    kernel's is that of its last iterate, the limit it approaches)."""
    d = x - nodes
    near = np.sum(d**2, axis=1) <= -np.log(tolerance) / gamma
    on_face = (x == 0) | (x == cells)
    support = near & np.all(np.abs(d[:, on_face]) == 0, axis=1)
    free = ~on_face
    offsets = d[support][:, free]
    weights = np.zeros(len(nodes))
    grad = np.zeros_like(nodes)
    grad[:, on_face] = np.nan
    if offsets.shape[1] == 0:
        weights[support] = 1.0
        return weights, grad
    prior = -gamma * np.sum(offsets**2, axis=1)

    def moments(mu):
        f = prior + offsets @ mu
        top = f.max()
        p = np.exp(f - top)
        z = p.sum()
        p /= z
        r = p @ offsets
        c = offsets - r
        return top + np.log(z), p, r, (c * p[:, None]).T @ c

    mu = np.zeros(offsets.shape[1])
    log_z, p, r, j = moments(mu)
    for _ in range(200):
        if np.linalg.norm(r) < LME_RESIDUAL / 10:
            break
        step = -np.linalg.solve(j, r)
        alpha = 1.0
        while alpha > 1e-12:
            trial = moments(mu + alpha * step)
            if trial[0] <= log_z + 1e-4 * alpha * (r @ step) + 1e-13 * (1 + abs(log_z)):
                break
            alpha /= 2
        mu = mu + alpha * step
        log_z, p, r, j = trial
    weights[support] = p
    block = -(np.linalg.solve(j, (offsets - r).T).T) * p[:, None]
    grad[np.ix_(support, free)] = block
    return weights, grad


def test_shape_functions_layout(run):
    run.require_shape_functions()
    a, g = run.attrs, run.group("/shape_functions")
    assert a["benchmark"] == "shape_functions"
    assert g["basis"] == a["method"] and g["basis"] in SHAPE_BASES
    for name in ("gamma", "tolerance", "radius") + tuple(f"max_{f}_error" for f in SHAPE_FIELDS):
        assert isinstance(g.get(name), (float, np.floating)), f"/shape_functions {name}"
    for name in ("centre", "failures", "max_newton_steps"):
        assert isinstance(g.get(name), (int, np.integer)), f"/shape_functions {name}"
    x = run.ds("/shape_functions/x")
    n_p, d = x.shape
    nodes = run.ds("/shape_functions/nodes")
    n_n = len(nodes)
    shapes = {
        "x": (n_p, d), "nodes": (n_n,), "node_x": (n_n, d), "value": (n_p, n_n),
        "gradient": (n_p, n_n, d),
    }
    shapes.update({f"{f}_error": (n_p,) for f in SHAPE_FIELDS})
    for name, shape in shapes.items():
        arr = run.ds(f"/shape_functions/{name}")
        assert arr.shape == shape, f"/shape_functions/{name} has shape {arr.shape}, not {shape}"
        assert run.units[f"/shape_functions/{name}"] == "1"
    assert np.issubdtype(nodes.dtype, np.integer)
    assert d == a["dim"] == run.values("/params")["dim"]
    if run.status != "ok":
        pytest.skip("the run did not complete")
    expected_x, cells = shape_lattice(run)
    np.testing.assert_array_equal(x, expected_x, err_msg="evaluation points")
    for f in SHAPE_FIELDS:
        errors = run.ds(f"/shape_functions/{f}_error")
        assert g[f"max_{f}_error"] == errors.max(), f"max_{f}_error is not the largest"
    assert g["failures"] == 0, "an ok run had Newton failures"
    if g["basis"] == "lme":
        radius = np.sqrt(-np.log(g["tolerance"]) / g["gamma"])
        np.testing.assert_allclose(g["radius"], radius, rtol=1e-15)
        assert 0 < g["max_newton_steps"] <= 100
    else:
        assert np.isnan(g["gamma"]) and g["max_newton_steps"] == 0


def test_shape_functions_by_a_second_implementation(run):
    run.require_shape_functions()
    g = run.group("/shape_functions")
    if run.status != "ok" or g["basis"] not in REIMPLEMENTED_BASES:
        pytest.skip("no second implementation of this basis, or the run did not complete")
    x, cells = shape_lattice(run)
    d = x.shape[1]
    nodes = grid_nodes(cells, d)
    centre = np.full(d, cells // 2)
    i = centre[0]
    along = np.arange(max(i - SHAPE_NEIGHBOURS, 0), min(i + SHAPE_NEIGHBOURS + 1, cells + 1))
    expected_nodes = [int(k + (cells + 1) * centre[1]) if d == 2 else int(k) for k in along]
    np.testing.assert_array_equal(run.ds("/shape_functions/nodes"), expected_nodes)
    np.testing.assert_array_equal(run.ds("/shape_functions/node_x"), nodes[expected_nodes])
    assert int(g["centre"]) == list(along).index(i)
    value = run.ds("/shape_functions/value")
    gradient = run.ds("/shape_functions/gradient")
    for p in range(len(x)):
        if g["basis"] == "linear":
            n, grad = hat(x[p], nodes)
            # At a cell face the hat's gradient is one-sided: the kernel takes the upper cell.
            if np.any(np.isclose(x[p] % 1.0, 0.0)):
                grad = None
        else:
            n, grad = lme(x[p], nodes, g["gamma"], g["tolerance"], cells)
        np.testing.assert_allclose(value[p], n[expected_nodes], rtol=0, atol=1e-10,
                                   err_msg=f"N_a at {x[p]}")
        if grad is not None:
            expected = grad[expected_nodes]
            known = ~np.isnan(expected)
            np.testing.assert_allclose(gradient[p][known], expected[known], rtol=0, atol=1e-8,
                                       err_msg=f"grad N_a at {x[p]}")
