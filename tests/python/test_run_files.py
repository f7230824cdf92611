"""Every run file: the results directory, the root attributes and identity, the configuration and
parameters; and that every benchmark the binary lists is checked against an oracle here or
named as having none.

Checks the run files under $MPMLAB_RESULTS against the HDF5 layout documented in the
README ("HDF5 layout", schema_version 2), using h5py and numpy only.

Besides names, types and shapes, it recomputes from the stored arrays:
  * the quadrature volumes  /errors/volume = volume0 * rho0 / density,
  * the grid's DOFs, their trapezoidal weights /grid/weight and the time level /grid/time of
    each sample's grid velocity,
  * every l2_* and rms_* norm and the final-value attributes of /errors/norms,
  * the pointwise errors themselves, from /history and /grid/v and an independent
    implementation of the manufactured solutions of Gong (mms1d_gong, mms2d_gong) and Tran
    (mms1d_tran), with the inverse motion by bisection for the grid velocity (the material
    point at each DOF at the sample time, its velocity at /grid/time),
  * the mass totals of /conservation against /particles/mass,
so that the exact solution and the error definitions are checked by a second implementation.

Reconstruction runs (recon1d_nodes, recon1d_basis) have a /reconstruction group instead of
/particles, /history and /errors. For them it recomputes the data points (re-implementing the
seeded generator), the sampled function, u^h by an independent weighted least-squares fit
(Gram-Schmidt on value vectors), the l2 and max norms, and the orthogonal basis with its
<p_i, p_i>.

Shape-function runs (shape_functions) have a /shape_functions group instead. For them it
recomputes the lattice of evaluation points and the recorded nodes, and N_a and grad N_a of
those nodes by a second implementation: the hat by its formula, the local maximum-entropy basis
by a damped Newton solve in numpy (on a face of the grid by the LME of the face's nodes alone,
the limit the kernel approaches), and checks the stored maxima of the consistency errors.

Element-wise runs (recon_tls) have an /elements group instead. For them it recomputes the
elements, the data points of each, the Gauss points and weights (numpy's Gauss-Legendre rule),
u there, each element's Taylor least-squares fit (numpy's SVD least squares, the element mean
by numerical quadrature, the degree by the rank of the basis at the data), u^h at the Gauss
points and at the plot and map samples, the RMS error and the relative integral error.

`make test` runs the reduced matrices in tests/matrices/ and points MPMLAB_RESULTS at them.
Without the variable, or with no *.h5 file under it, the suite fails (it never passes empty).
"""

import numpy as np
import pytest

from catalog import BENCHMARK_KINDS, REFERENCE_METHODS
from layout import (
    ENV, FLOAT_ATTRS, INT_ATTRS, RTOL_STORED, RUN_FILES, RUN_ID, SCHEMA_VERSION,
    SIMULATION_FLOAT_ATTRS, SIMULATION_INT_ATTRS, SIMULATION_STR_ATTRS, STATUSES, STR_ATTRS,
    _as_str, _results_root,
)
from manufactured import BENCHMARKS
from sampling import RECONSTRUCTION


def test_run_files_present():
    root = _results_root()
    assert root is not None, (
        f"{ENV} is not set: point it at a directory of mpmlab results "
        "(`make test` does this for the reduced matrices in tests/matrices/)"
    )
    assert root.is_dir(), f"{ENV}={root} is not a directory"
    assert RUN_FILES, f"no *.h5 run files under {ENV}={root}"


def test_no_leftover_files_in_runs_dirs():
    """Run files and their XDMF descriptions are written under a temporary name and renamed
    when complete, and each run's lock file goes when its run is written, so a finished
    `mpmlab run` leaves nothing but <run_id>.h5, <run_id>.xdmf and the record of the
    experiment file (.experiment-source) in each runs/ directory."""
    root = _results_root()
    if root is None or not root.is_dir():
        pytest.fail(f"{ENV} is not set or not a directory")
    stray = [
        str(p)
        for runs in root.rglob("runs")
        if runs.is_dir()
        for p in runs.iterdir()
        if not (p.is_file() and (p.suffix in (".h5", ".xdmf") or p.name == ".experiment-source"))
    ]
    assert not stray, f"unexpected entries in runs/ directories: {stray}"



# --------------------------------------------------------------------------------------------
# Attributes and identity


def test_root_attributes(run):
    a = run.attrs
    strs, ints, floats = STR_ATTRS, INT_ATTRS, FLOAT_ATTRS
    if not run.is_unstepped:
        strs += SIMULATION_STR_ATTRS
        ints += SIMULATION_INT_ATTRS
        floats += SIMULATION_FLOAT_ATTRS
    for name in strs + ints + floats:
        assert name in a, f"missing root attribute {name}"
        assert np.asarray(a[name]).shape == (), f"root attribute {name} is not a scalar"
    for name in strs:
        assert isinstance(a[name], str), f"{name} is not a string: {a[name]!r}"
    for name in ints:
        v = a[name]
        assert isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_)), (
            f"{name} is not an integer: {v!r} ({type(v).__name__})"
        )
    for name in floats:
        assert isinstance(a[name], (float, np.floating)), (
            f"{name} is not a float: {a[name]!r} ({type(a[name]).__name__})"
        )
        assert np.isfinite(a[name]), f"{name} is not finite: {a[name]}"
    if run.is_unstepped:
        for name in SIMULATION_STR_ATTRS + SIMULATION_INT_ATTRS + SIMULATION_FLOAT_ATTRS:
            assert name not in a, f"reconstruction run with the simulation attribute {name}"

    assert a["schema_version"] == SCHEMA_VERSION
    assert a["status"] in STATUSES, f"status {a['status']!r} not in {STATUSES}"
    if a["status"] == "diverged":
        assert a["message"].strip(), "a diverged run must say where and why in `message`"
    for name in ("run_id", "experiment", "benchmark", "method", "mpmlab_version"):
        assert a[name].strip(), f"{name} is empty"
    assert a["dim"] in (1, 2, 3)
    assert a["cells"] >= 1 and a["h"] > 0 and a["wall_seconds"] >= 0
    # The median step time: of the MPM time loop only, and only when it completed a step.
    assert "step_seconds" in a
    stepped = not run.is_unstepped and a["method"] not in REFERENCE_METHODS and a["steps"] > 0
    if stepped:
        assert 0 < a["step_seconds"] <= a["wall_seconds"]
    elif run.is_unstepped or a["method"] in REFERENCE_METHODS:
        assert np.isnan(a["step_seconds"])
    if run.is_reconstruction:
        # ppc is 0 when the points are given in the experiment file (recon1d_basis).
        assert a["dim"] == 1 and a["ppc"] >= 0
    elif run.is_elements:
        assert a["dim"] in (1, 2) and a["ppc"] >= 1
    elif run.is_shape_functions:
        assert a["dim"] in (1, 2) and a["ppc"] == 0 and a["h"] == 1.0
    else:
        assert a["ppc"] >= 1 and a["steps"] >= 0
        assert a["dt"] > 0 and a["t_end"] > 0


def test_identity(run):
    a = run.attrs
    assert run.path.stem == a["run_id"], "file name must be <run_id>.h5"
    assert RUN_ID.match(a["run_id"]), (
        f"run_id {a['run_id']!r} is not <method>-<axis values>-<12 hex digits>"
    )
    assert a["run_id"].startswith(a["method"] + "-"), "run_id must start with the method"
    if run.path.parent.name == "runs":
        assert run.path.parent.parent.name == a["experiment"], (
            "run files live in <out>/<experiment>/runs/"
        )
    bench = BENCHMARKS.get(a["benchmark"])
    if bench is not None:
        assert a["dim"] == bench.dim, f"{a['benchmark']} has dim {bench.dim}"


def test_config_yaml_dataset(run):
    """The resolved configuration is a scalar string dataset (an attribute cannot hold a long
    one), the YAML of the run's experiment and benchmark."""
    assert "config_yaml" not in run.attrs, "config_yaml is a dataset, not a root attribute"
    text = _as_str(run.ds("/config_yaml"))
    assert isinstance(text, str), f"/config_yaml is not a string: {text!r}"
    lines = text.splitlines()
    assert f"experiment: {run.attrs['experiment']}" in lines, lines[:3]
    assert f"benchmark: {run.attrs['benchmark']}" in lines, lines[:3]


def test_params_and_matrix(run):
    a = run.attrs
    for name in ("/params", "/matrix"):
        for key, value in run.group(name).items():
            assert np.asarray(value).ndim == 0, f"{name} attribute {key} is not a scalar"
    params = run.values("/params")
    matrix = run.values("/matrix")
    assert params, "/params has no values"
    bench = BENCHMARKS.get(a["benchmark"])
    if bench is not None:
        for key in bench.params + ("rho0", "t_end", "ppc", "cells"):
            run.param(key)
        assert run.param("cells") == a["cells"]
        assert run.param("ppc") == a["ppc"]
        np.testing.assert_allclose(run.param("t_end"), a["t_end"], rtol=1e-15)
        np.testing.assert_allclose(a["h"], bench.length(run) / a["cells"], rtol=RTOL_STORED)
        assert a["dt"] <= bench.max_dt(run) * (1 + 1e-9), "dt exceeds the requested step"
    for key, value in matrix.items():
        # Scalars, or 1-D float datasets for list-valued parameters (point coordinates).
        assert np.asarray(value).ndim <= 1, f"/matrix/{key} is neither a scalar nor a list"
        if key == "method":
            assert value == a["method"], f"/matrix method {value!r} != root method"
        else:
            assert key in params, f"matrix axis {key} is not a parameter in /params"
            if isinstance(value, str):
                assert value == params[key], f"/matrix/{key} != /params/{key}"
            else:
                np.testing.assert_allclose(
                    np.asarray(value, dtype=float),
                    np.asarray(params[key], dtype=float),
                    rtol=1e-15,
                    err_msg=f"/matrix/{key}",
                )



# What each benchmark's numbers are checked against here, by a second implementation.
ORACLES = {
    **{name: "the manufactured solution, pointwise (sine_exact)" for name in BENCHMARKS},
    **{name: "an independent least-squares fit (reconstruct_at)" for name in RECONSTRUCTION},
    "recon_tls": "each element's Taylor fit by numpy's SVD least squares",
    "shape_functions": "the hat's formula and a numpy LME Newton solve",
    "dyka_bar": "d'Alembert's solution at the probes (dyka_reference)",
    "andersen_block": "the static column at the probes (andersen_reference)",
}
# Benchmarks checked for their layout and self-consistency only, with the reason.
WITHOUT_ORACLE = {
    "vibrating_bar": "its exact solution is the benchmark's own (Wobbes et al. eq 15); the "
                     "errors are checked against the stored history, not re-derived",
}


def test_every_benchmark_has_an_oracle_or_is_listed_without_one():
    """A benchmark the binary lists is either checked by a second implementation here or named
    in WITHOUT_ORACLE: none is skipped because a list here missed it."""
    for name, kind in BENCHMARK_KINDS.items():
        assert (name in ORACLES) != (name in WITHOUT_ORACLE), (
            f"{name} ({kind}): give it an oracle in ORACLES or a reason in WITHOUT_ORACLE"
        )
    stale = (set(ORACLES) | set(WITHOUT_ORACLE)) - set(BENCHMARK_KINDS)
    assert not stale, f"listed here but not a benchmark of the binary: {sorted(stale)}"
