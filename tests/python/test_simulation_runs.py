"""Simulation runs: datasets, sampling, particles, mass totals, diagnostics, the stored errors
against the stored states, the grid DOFs and time levels, and the pointwise errors against the
manufactured solutions.
"""

import numpy as np
import pytest

from catalog import DOF_DEGREES, REFERENCE_METHODS, conserves, method_parts
from layout import (
    CENTRED_INTEGRATORS, DIAGNOSTICS, FIELDS, GRID_FIELD, HALF_STEP_INTEGRATORS, MASS_UNITS,
    NORMS, RTOL_STORED, _as_str,
)
from manufactured import BENCHMARKS, _check_pointwise, grid_exact_velocity, sine_exact


# --------------------------------------------------------------------------------------------
# Datasets


def _part_of(run):
    """The lookup of the run's part parameters that `method_parts` takes: a name or None."""
    params = run.values("/params")
    return lambda key: _as_str(params[key]) if key in params else None


def _expected_shapes(run):
    X = run.ds("/particles/X")
    assert X.ndim == 2, f"/particles/X must be (Np, D), is {X.shape}"
    n_p, d = X.shape
    n_t = run.ds("/history/time").shape[0]
    n_e = run.ds("/errors/time").shape[0]
    shapes = {
        "/particles/X": (n_p, d),
        "/particles/mass": (n_p,),
        "/particles/volume0": (n_p,),
        "/history/time": (n_t,),
        "/history/step": (n_t,),
        "/history/x": (n_t, n_p, d),
        "/history/v": (n_t, n_p, d),
        "/history/stress": (n_t, n_p, d, d),
        "/history/density": (n_t, n_p),
        "/errors/time": (n_e,),
        "/errors/volume": (n_e, n_p),
        "/conservation/time": (n_t,),
        "/conservation/particle_mass": (n_t,),
        "/conservation/grid_mass": (n_t,),
    }
    n_n = run.ds("/grid/weight").shape[0]
    shapes.update({
        "/grid/x": (n_n, d),
        "/grid/weight": (n_n,),
        "/grid/time": (n_t,),
        "/grid/v": (n_t, n_n, d),
    })
    for field, points in [(f, n_p) for f in FIELDS] + [(GRID_FIELD, n_n)]:
        shapes[f"/errors/{field}"] = (n_e, points)
        for norm in NORMS:
            shapes[f"/errors/norms/{norm}_{field}"] = (n_e,)
    return shapes


def test_datasets_shapes_types_units(run):
    run.require_data()
    a = run.attrs
    shapes = _expected_shapes(run)
    d = shapes["/particles/X"][1]
    assert d == a["dim"], f"/particles/X has {d} columns, dim is {a['dim']}"
    for name, shape in shapes.items():
        arr = run.ds(name)
        assert arr.shape == shape, f"{name} has shape {arr.shape}, expected {shape}"
        if name == "/history/step":
            assert np.issubdtype(arr.dtype, np.integer), f"{name} dtype {arr.dtype} is not int"
        else:
            assert arr.dtype == np.float64, f"{name} dtype {arr.dtype} is not float64"
    for name, units in run.units.items():
        # The configuration and list-valued parameters are inputs, not physical arrays.
        if name == "/config_yaml" or name.startswith(("/params/", "/matrix/")):
            continue
        assert isinstance(units, str), f"dataset {name} has no string `units` attribute"
    n_p = shapes["/particles/X"][0]
    assert n_p >= 1
    assert shapes["/history/time"][0] >= 2, "history holds at least t = 0 and the final time"
    if a["benchmark"] in BENCHMARKS:
        assert n_p == (a["cells"] * a["ppc"]) ** a["dim"], "Np != (cells * ppc)^dim"


def test_sampling(run):
    run.require_data()
    a = run.attrs
    time = run.ds("/history/time")
    step = run.ds("/history/step")
    assert time[0] == 0.0, f"history starts at t = {time[0]}, not 0"
    assert step[0] == 0
    assert np.all(np.diff(step) > 0), "history steps are not strictly increasing"
    assert np.all(np.diff(time) > 0), "history times are not strictly increasing"
    if a["status"] == "ok":
        assert step[-1] == a["steps"], f"last sampled step {step[-1]} != steps {a['steps']}"
    else:
        # A diverged run keeps the samples taken before the step that failed.
        assert step[-1] <= a["steps"], f"sample at step {step[-1]} after the last step {a['steps']}"
    np.testing.assert_allclose(time, step * a["dt"], rtol=0, atol=1e-6 * a["dt"])
    gaps = np.diff(step)
    if gaps.size > 1:
        assert np.all(gaps[:-1] == gaps[0]), f"uneven sampling interval: {gaps}"
        assert gaps[-1] <= gaps[0], f"last interval {gaps[-1]} exceeds output.every {gaps[0]}"
    if a["status"] == "ok":
        np.testing.assert_allclose(time[-1], a["t_end"], rtol=1e-9, err_msg="final time")
        np.testing.assert_allclose(a["steps"] * a["dt"], a["t_end"], rtol=1e-12)
    np.testing.assert_array_equal(
        run.ds("/errors/time"), time, err_msg="/errors/time differs from /history/time"
    )


def test_particles(run):
    run.require_data()
    X = run.ds("/particles/X")
    mass = run.ds("/particles/mass")
    vol0 = run.ds("/particles/volume0")
    assert np.all(mass > 0) and np.all(vol0 > 0)
    bench = BENCHMARKS.get(run.attrs["benchmark"])
    if bench is not None:
        length = bench.length(run)
        volume = length ** bench.dim
        assert np.all((X > 0) & (X < length)), "reference positions outside the domain"
        np.testing.assert_allclose(
            mass.sum(), run.param("rho0") * volume, rtol=RTOL_STORED, err_msg="mass"
        )
        np.testing.assert_allclose(vol0.sum(), volume, rtol=RTOL_STORED, err_msg="volume0")
        # The history starts in the reference configuration.
        np.testing.assert_array_equal(run.ds("/history/x")[0], X)


# --------------------------------------------------------------------------------------------
# Mass totals and reconstruction counters


def test_conservation(run):
    run.require_data()
    np.testing.assert_array_equal(
        run.ds("/conservation/time"), run.ds("/history/time"),
        err_msg="/conservation/time differs from /history/time",
    )
    assert run.units["/conservation/time"] == "s"
    for name in ("particle_mass", "grid_mass"):
        assert run.units[f"/conservation/{name}"] == MASS_UNITS, f"/conservation/{name} units"
    particle = run.ds("/conservation/particle_mass")
    grid = run.ds("/conservation/grid_mass")
    # Particle masses never change, and the total is summed in the same order every time.
    np.testing.assert_array_equal(particle, particle[0], err_msg="particle mass is not constant")
    np.testing.assert_allclose(
        particle, run.ds("/particles/mass").sum(), rtol=RTOL_STORED,
        err_msg="/conservation/particle_mass != sum of /particles/mass",
    )
    assert np.all(np.isfinite(grid)) and np.all(grid > 0), "grid mass is not positive"
    if run.attrs["method"] == "mpm":
        # The original MPM lumps each particle's mass onto nodes with weights summing to one.
        np.testing.assert_allclose(
            grid, particle, rtol=1e-12, atol=0, err_msg="mpm grid mass != particle mass"
        )
    # The largest relative mass and momentum errors of any mapping of the run. Methods that
    # conserve both (lumped Shepard mappings and TLS) must stay within a summation bound:
    # a few rounding errors per particle and DOF.
    errors = run.group("/conservation")
    for name in ("max_mass_error", "max_momentum_error"):
        assert name in errors, f"/conservation has no attribute {name}"
        if run.attrs["method"] in REFERENCE_METHODS:
            # A reference solver maps nothing from particles to a grid.
            assert np.isnan(errors[name]), f"{name} = {errors[name]} for a reference solver"
        elif run.status == "ok":
            assert np.isfinite(errors[name]) and errors[name] >= 0, f"{name} = {errors[name]}"
    if run.status == "ok" and conserves(run.attrs["method"], _part_of(run)):
        dofs = (int(run.attrs["cells"]) + 3) ** int(run.attrs["dim"])
        bound = 4 * np.finfo(float).eps * (len(run.ds("/particles/mass")) + dofs)
        for name in ("max_mass_error", "max_momentum_error"):
            assert errors[name] <= bound, f"{name} = {errors[name]:.3e} > {bound:.3e}"


def test_diagnostics(run):
    if run.is_unstepped:
        pytest.skip("run without particles: its counters are in its own group")
    counters = run.group("/diagnostics")
    for name in DIAGNOSTICS:
        assert name in counters, f"/diagnostics has no attribute {name}"
        v = counters[name]
        assert isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_)), (
            f"/diagnostics {name} is not an integer: {v!r}"
        )
        assert v >= 0, f"/diagnostics {name} = {v} < 0"
    assert counters["rank_deficient"] <= counters["reconstructions"]
    if run.attrs["method"] == "mpm":
        assert counters["reconstructions"] == 0 and counters["rank_deficient"] == 0, (
            "the original MPM makes no least-squares fits"
        )
    if not str(run.attrs["shape"]).startswith("lme"):
        assert counters["lme_failures"] == 0, "only the LME basis solves for its weights"
    elif counters["lme_failures"] > 0:
        assert "lme_failures" in str(run.attrs["message"]), "LME failures must be named in message"


# --------------------------------------------------------------------------------------------
# Stored errors against the stored states


def test_error_volumes(run):
    run.require_data()
    rho0 = run.param("rho0")
    expected = run.ds("/particles/volume0")[None, :] * rho0 / run.ds("/history/density")
    np.testing.assert_allclose(
        run.ds("/errors/volume"), expected, rtol=RTOL_STORED, atol=0, equal_nan=True,
        err_msg="/errors/volume != volume0 * rho0 / density",
    )


def test_norms(run):
    run.require_data()
    volume = run.ds("/errors/volume")
    n_p = volume.shape[1]
    grid_weight = run.ds("/grid/weight")[None, :]
    n_n = grid_weight.shape[1]
    final = run.group("/errors/norms")
    for field in FIELDS + (GRID_FIELD,):
        e = run.ds(f"/errors/{field}")
        finite = np.isfinite(e)
        assert np.all(e[finite] >= 0), f"/errors/{field} holds negative magnitudes"
        if field == GRID_FIELD:
            # Over the DOFs where the exact velocity is known: all of them for the manufactured
            # solutions, none (NaN norms) elsewhere.
            if run.attrs["benchmark"] not in BENCHMARKS or n_n == 0:
                assert np.all(np.isnan(e)), "a grid-velocity error without an exact one"
                nan = np.full(e.shape[0], np.nan)
                recomputed = {"l2": nan, "rms": nan}
            else:
                recomputed = {
                    "l2": np.sqrt(np.sum(grid_weight * e**2, axis=1)),
                    "rms": np.sqrt(np.sum(e**2, axis=1) / n_n),
                }
        else:
            recomputed = {
                "l2": np.sqrt(np.sum(volume * e**2, axis=1)),
                "rms": np.sqrt(np.sum(e**2, axis=1) / n_p),
            }
        for norm in NORMS:
            name = f"{norm}_{field}"
            stored = run.ds(f"/errors/norms/{name}")
            np.testing.assert_allclose(
                stored, recomputed[norm], rtol=RTOL_STORED, atol=0, equal_nan=True,
                err_msg=f"/errors/norms/{name}",
            )
            assert name in final, f"/errors/norms has no attribute {name}"
            value = final[name]
            assert np.asarray(value).shape == () and isinstance(value, (float, np.floating)), (
                f"/errors/norms attribute {name} is not a float scalar"
            )
            np.testing.assert_allclose(
                value, stored[-1], rtol=RTOL_STORED, atol=0, equal_nan=True,
                err_msg=f"final value attribute {name}",
            )


def _axis_coordinates(x, d, per_axis):
    """The DOF coordinates along each axis of a lattice numbered with the first axis fastest."""
    strides = [per_axis**k for k in range(d)]
    return [x[[i * strides[k] for i in range(per_axis)], k] for k in range(d)]


def test_grid_dofs_and_weights(run):
    """/grid/x is the lattice of the basis' DOFs (the nodes, or a B-spline's Greville
    abscissae, the means of its interior knots: 0, h/2, 3h/2, ..., L - h/2, L for the quadratic),
    first axis fastest, and /grid/weight the trapezoidal rule over it, which sums to the volume
    of the grid."""
    run.require_data()
    a = run.attrs
    x = run.ds("/grid/x")
    weight = run.ds("/grid/weight")
    assert run.units["/grid/x"] == "m" and run.units["/grid/weight"] == "m^D"
    if a["method"] in REFERENCE_METHODS:
        assert x.shape[0] == 0, "a reference solver has no grid"
        return
    d, h = int(a["dim"]), float(a["h"])
    # The hat and the bases built on it have a DOF per node, a B-spline of degree p cells + p.
    shape, _ = method_parts(a["method"], _part_of(run))
    degree = DOF_DEGREES[shape]
    # The grid may reach beyond the body (empty cells for it to move into), so its cells are
    # read from the lattice, not from the `cells` parameter.
    per_axis = int(round(x.shape[0] ** (1.0 / d)))
    assert x.shape[0] == per_axis**d, f"{x.shape[0]} DOFs are not a {d}-dimensional lattice"
    cells = per_axis - degree
    assert cells >= int(a["cells"]), f"{cells} grid cells for a body of {a['cells']}"
    lower = x[0]
    # Knots t_j = clamp(j - p, 0, cells); DOF i at the mean of t_(i+1), ..., t_(i+p).
    knots = np.clip(np.arange(per_axis + degree + 1) - degree, 0, cells)
    steps = np.array([knots[i + 1:i + degree + 1].mean() for i in range(per_axis)])
    axes = _axis_coordinates(x, d, per_axis)
    for k in range(d):
        np.testing.assert_allclose(
            axes[k], lower[k] + steps * h, rtol=0, atol=1e-12 * cells * h,
            err_msg=f"/grid/x along axis {k}",
        )
    index = np.arange(per_axis**d)
    expected = np.ones(per_axis**d)
    for k in range(d):
        c = axes[k]
        w = 0.5 * (np.append(c[1:], c[-1]) - np.insert(c[:-1], 0, c[0]))
        expected *= w[(index // per_axis**k) % per_axis]
    np.testing.assert_allclose(weight, expected, rtol=RTOL_STORED, err_msg="/grid/weight")
    np.testing.assert_allclose(weight.sum(), (cells * h) ** d, rtol=1e-12)


def test_grid_time(run):
    """The grid velocity of a sample belongs to t + dt/2 where velocities are half-step ones
    and to t + dt where they are whole-step ones."""
    run.require_data()
    a = run.attrs
    if a["method"] in REFERENCE_METHODS:
        pytest.skip("a reference solver has no grid")
    sampled = run.values("/params").get("sampled_velocity", "stepped")
    integrator = str(a["integrator"])
    half = integrator in HALF_STEP_INTEGRATORS or (
        integrator in CENTRED_INTEGRATORS and sampled == "centred"
    )
    lag = 0.5 if half else 1.0
    np.testing.assert_allclose(
        run.ds("/grid/time"), run.ds("/history/time") + lag * a["dt"], rtol=1e-12,
        err_msg=f"/grid/time of integrator {integrator}",
    )
    assert run.units["/grid/time"] == "s" and run.units["/grid/v"] == "m/s"



def test_exact_errors(run):
    run.require_data()
    benchmark = run.attrs["benchmark"]
    if benchmark not in BENCHMARKS:
        pytest.skip(f"no independent exact solution for {benchmark}")
    X = run.ds("/particles/X")
    t = run.ds("/history/time")
    u, v, sigma, rho = sine_exact(X, t, BENCHMARKS[benchmark].wave(run))

    disp = run.ds("/history/x") - X[None]
    vel = run.ds("/history/v")
    stress = run.ds("/history/stress")
    dens = run.ds("/history/density")
    pairs = {
        "displacement": (disp, u, np.linalg.norm(disp - u, axis=-1)),
        "velocity": (vel, v, np.linalg.norm(vel - v, axis=-1)),
        "stress": (stress, sigma, np.sqrt(np.sum((stress - sigma) ** 2, axis=(-2, -1)))),
        "density": (dens, rho, np.abs(dens - rho)),
    }
    for field, (numerical, exact, recomputed) in pairs.items():
        _check_pointwise(field, run.ds(f"/errors/{field}"), recomputed, numerical, exact)
    x = run.ds("/grid/x")
    grid_v = run.ds("/grid/v")
    exact = grid_exact_velocity(x, t, run.ds("/grid/time"), BENCHMARKS[benchmark].wave(run))
    recomputed = np.linalg.norm(grid_v - exact, axis=-1)
    _check_pointwise(GRID_FIELD, run.ds(f"/errors/{GRID_FIELD}"), recomputed, grid_v, exact)
    if run.status == "ok":
        # At t = 0 the particles sit at X with the exact initial velocity and zero stress.
        np.testing.assert_array_equal(run.ds("/errors/displacement")[0], 0.0)
