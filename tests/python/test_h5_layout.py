"""Checks the run files under $MPMLAB_RESULTS against the HDF5 layout documented in the
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

import csv
import os
import re
from pathlib import Path
from typing import Callable, NamedTuple

import h5py
import numpy as np
import pytest

ENV = "MPMLAB_RESULTS"
SCHEMA_VERSION = 3

STR_ATTRS = (
    "run_id",
    "experiment",
    "benchmark",
    "method",
    "status",
    "message",
    "mpmlab_version",
)
INT_ATTRS = ("schema_version", "dim", "cells", "ppc")
FLOAT_ATTRS = ("h", "wall_seconds")
# Root attributes of simulation runs only (a reconstruction run does not step).
SIMULATION_STR_ATTRS = ("shape", "transfer", "integrator")
SIMULATION_INT_ATTRS = ("steps",)
SIMULATION_FLOAT_ATTRS = ("dt", "t_end")
STATUSES = ("ok", "diverged", "failed")

FIELDS = ("displacement", "velocity", "stress", "density")
GRID_FIELD = "grid_velocity"
NORMS = ("l2", "rms")
# Integrators whose grid solve gives the half-step velocity v^{s+1/2} at a sample (the
# predictor-corrector's predictor included); MUSL and USL too when read as centred.
HALF_STEP_INTEGRATORS = ("leapfrog", "predictor_corrector")
CENTRED_INTEGRATORS = ("musl", "usl")

MASS_UNITS = "kg"
# Solvers that are not MPM (their run files have one point per element, no mapping).
REFERENCE_METHODS = ("ulfem",)
# Methods whose mappings conserve mass and momentum to round-off.
CONSERVATIVE_METHODS = (
    "mpm", "mpm_musl", "mpm_tls", "mpm_tls_lumped", "bsmpm", "bsmpm_consistent", "bsmpm_tls",
    "bsmpm_tls_lumped", "ddmpm", "ddmpm_cells", "ddmpm_tls", "ddmpm_tls_lumped",
)
DIAGNOSTICS = ("reconstructions", "rank_deficient", "grid_crossings", "lme_failures")

RUN_ID = re.compile(r"^.+-[0-9a-f]{12}$")

# Recomputed quantities agree with the stored ones to this relative tolerance.
RTOL_STORED = 1e-12
# Pointwise errors from a second implementation: tolerance relative to the field's scale.
RTOL_FIELD = 1e-9


def _results_root():
    root = os.environ.get(ENV)
    return Path(root) if root else None


def _find_run_files():
    root = _results_root()
    if root is None or not root.is_dir():
        return []
    return sorted(root.rglob("*.h5"))


RUN_FILES = _find_run_files()


def _file_id(path):
    root = _results_root()
    try:
        return str(path.relative_to(root))
    except ValueError:
        return str(path)


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
# Loading


def _as_str(value):
    if isinstance(value, bytes):  # fixed-length strings come back as numpy.bytes_
        return value.decode("utf-8")
    return value


class Run:
    """Everything in one run file, read into memory once."""

    def __init__(self, path):
        self.path = path
        self.attrs = {}
        self.groups = {}  # "/group" -> its attributes
        self.data = {}  # "/group/dataset" -> numpy array
        self.units = {}  # "/group/dataset" -> units attribute (None when missing)
        with h5py.File(path, "r") as f:
            self.attrs = {k: _as_str(v) for k, v in f.attrs.items()}

            def visit(name, obj):
                key = "/" + name
                if isinstance(obj, h5py.Dataset):
                    self.data[key] = obj[()]
                    self.units[key] = _as_str(obj.attrs.get("units"))
                else:
                    self.groups[key] = {k: _as_str(v) for k, v in obj.attrs.items()}

            f.visititems(visit)

    def ds(self, name):
        assert name in self.data, f"missing dataset {name}"
        return self.data[name]

    def group(self, name):
        assert name in self.groups, f"missing group {name}"
        return self.groups[name]

    @property
    def status(self):
        return self.attrs.get("status")

    @property
    def is_reconstruction(self):
        return "/reconstruction" in self.groups

    @property
    def is_elements(self):
        return "/elements" in self.groups

    @property
    def is_shape_functions(self):
        return "/shape_functions" in self.groups

    @property
    def is_unstepped(self):
        """Reconstruction runs, nodal or element-wise, and shape-function runs take no time
        steps."""
        return self.is_reconstruction or self.is_elements or self.is_shape_functions

    def has_data(self):
        """A failed run may stop before any state exists; every other run has all datasets."""
        if self.status == "failed" and "/history/time" not in self.data:
            return False
        return True

    def require_data(self):
        """Skips the checks of particle states for runs that have none."""
        if self.is_unstepped:
            pytest.skip("reconstruction run: no particles, history or errors")
        if not self.has_data():
            pytest.skip("failed run without stored states")

    def require_reconstruction(self):
        if not self.is_reconstruction:
            pytest.skip("no /reconstruction group")

    def require_elements(self):
        if not self.is_elements:
            pytest.skip("no /elements group")

    def require_shape_functions(self):
        if not self.is_shape_functions:
            pytest.skip("no /shape_functions group")

    def values(self, name):
        """A group's parameter values: its attributes (scalars) and its datasets (lists)."""
        values = dict(self.group(name))
        for key, value in self.data.items():
            parent, _, leaf = key.rpartition("/")
            if parent == name:
                values[leaf] = value
        return values

    def param(self, key):
        params = self.values("/params")
        assert key in params, f"/params has no attribute {key}"
        value = params[key]
        assert np.asarray(value).shape == (), f"/params/{key} is not a scalar"
        assert isinstance(value, (int, float, np.integer, np.floating)), (
            f"/params/{key} is not a number: {value!r}"
        )
        return float(value)


@pytest.fixture(scope="module", params=RUN_FILES, ids=[_file_id(p) for p in RUN_FILES])
def run(request):
    return Run(request.param)


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


# --------------------------------------------------------------------------------------------
# Datasets


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
    if run.status == "ok" and run.attrs["method"] in CONSERVATIVE_METHODS:
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
    """/grid/x is the lattice of the basis' DOFs (the nodes, or the quadratic B-spline's
    Greville abscissae 0, h/2, 3h/2, ..., L - h/2, L), first axis fastest, and /grid/weight the
    trapezoidal rule over it, which sums to the volume of the grid."""
    run.require_data()
    a = run.attrs
    x = run.ds("/grid/x")
    weight = run.ds("/grid/weight")
    assert run.units["/grid/x"] == "m" and run.units["/grid/weight"] == "m^D"
    if a["method"] in REFERENCE_METHODS:
        assert x.shape[0] == 0, "a reference solver has no grid"
        return
    d, h = int(a["dim"]), float(a["h"])
    spline = str(a["shape"]) == "quadratic-bspline"
    # The grid may reach beyond the body (empty cells for it to move into), so its cells are
    # read from the lattice, not from the `cells` parameter.
    per_axis = int(round(x.shape[0] ** (1.0 / d)))
    assert x.shape[0] == per_axis**d, f"{x.shape[0]} DOFs are not a {d}-dimensional lattice"
    cells = per_axis - (2 if spline else 1)
    assert cells >= int(a["cells"]), f"{cells} grid cells for a body of {a['cells']}"
    lower = x[0]
    steps = np.concatenate(([0.0], np.arange(per_axis - 2) + 0.5, [cells])) if spline else (
        np.arange(per_axis, dtype=float)
    )
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


# --------------------------------------------------------------------------------------------
# Reconstruction runs: a second implementation of the data, the fit, the norms and the basis

RECONSTRUCTION = ("recon1d_nodes", "recon1d_basis")
RECONSTRUCTION_DATASETS = (
    "x", "exact", "reconstructed", "error", "data_x", "data_u", "curve_x", "curve_u",
)
BASIS_DATASETS = ("coefficients", "norms", "kept", "data_weight", "data_p", "curve_p")
# The same criterion as the fits: a polynomial is dropped when <p, p> <= RANK * <q, q>.
RANK = 1e-10
DEGREES = {"shepard": 0, "mls_linear": 1, "mls_quadratic": 2, "imls_linear": 1,
           "imls_quadratic": 2}

FUNCTIONS = {
    "one": lambda x: np.ones_like(x),
    "x": lambda x: x,
    "x2": lambda x: x * x,
    "sin_pi": lambda x: np.sin(np.pi * x),
    "x_plus_1": lambda x: x + 1.0,
    "const_1_5": lambda x: np.full_like(x, 1.5),
    "sin_plus_2": lambda x: np.sin(x) + 2.0,
}


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


class Lcg:
    """mpmlab's generator: x <- 6364136223846793005 x + 1442695040888963407 mod 2^64, the top
    53 bits as the fraction of a uniform number in [0, 1)."""

    def __init__(self, seed):
        self.state = seed

    def unit(self):
        self.state = (6364136223846793005 * self.state + 1442695040888963407) % 2**64
        return (self.state >> 11) / 2.0**53


def cell_fractions(spacing, c, n, rng):
    """Where the n points of cell c go along one axis, as sorted fractions of the cell: equal
    (cell-centred sub-intervals), interior (j/(n+1)), random, or mixed (Wobbes Fig 1: edges
    and draws in cell 0, the left edge and draws in cell 1, equal in cell 2, random after)."""
    if spacing == "equal" or (spacing == "mixed" and c == 2):
        f = [(j + 0.5) / n for j in range(n)]
    elif spacing == "interior":
        f = [j / (n + 1) for j in range(1, n + 1)]
    elif spacing == "mixed" and c == 0:
        f = [0.0, 1.0] + [rng.unit() for _ in range(n - 2)]
    elif spacing == "mixed" and c == 1:
        f = [0.0] + [rng.unit() for _ in range(n - 1)]
    else:
        assert spacing in ("random", "mixed"), spacing
        f = [rng.unit() for _ in range(n)]
    return sorted(f)


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


# --------------------------------------------------------------------------------------------
# Shape-function runs: the lattice, the recorded nodes, and N_a and grad N_a by a second
# implementation of the hat and of the local maximum-entropy basis.

SHAPE_FIELDS = ("partition", "moment", "gradient", "gradient_moment")
SHAPE_BASES = ("lme", "linear", "quadratic_bspline")
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
    if run.status != "ok" or g["basis"] == "quadratic_bspline":
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


# Probes: every-step records at single particles (/probes/<name>)

PROBE_QUANTITIES = {"displacement": 1, "velocity": 1, "stress": 2}  # -> component indices
PROBE_UNITS = {"displacement": "m", "velocity": "m/s", "stress": "Pa"}
PROBE_REFERENCES = ("exact", "static", "none")
# Benchmarks whose simulation runs must record these probes.
PROBED = {
    "dyka_bar": ("free_end_velocity", "mid_stress", "quarter_stress"),
    "andersen_block": ("bottom_stress", "top_displacement"),
}


def _probes(run):
    names = sorted(
        key.split("/")[2] for key in run.groups if key.startswith("/probes/")
    )
    return names


def _require_probes(run):
    run.require_data()
    expected = PROBED.get(run.attrs["benchmark"])
    if expected is not None and run.attrs["method"] not in REFERENCE_METHODS:
        assert tuple(_probes(run)) == expected, f"probes {_probes(run)}, expected {expected}"
    if "/probes" not in run.groups:
        pytest.skip("no /probes group")
    assert run.attrs["method"] not in REFERENCE_METHODS, "reference solvers record no probes"


def _probe_quantity(run, name, t_index=None):
    """The probe's quantity from /history at its particle: (Nt_history,) values."""
    g = run.group(f"/probes/{name}")
    p = int(g["particle"])
    comp = [int(k) for k in np.atleast_1d(g["component"])]
    X = run.ds("/particles/X")
    if g["quantity"] == "displacement":
        return run.ds("/history/x")[:, p, comp[0]] - X[p, comp[0]]
    if g["quantity"] == "velocity":
        return run.ds("/history/v")[:, p, comp[0]]
    return run.ds("/history/stress")[:, p, comp[0], comp[1]]


def test_probes_layout(run):
    _require_probes(run)
    a = run.attrs
    X = run.ds("/particles/X")
    for name in _probes(run):
        base = f"/probes/{name}"
        g = run.group(base)
        quantity = g["quantity"]
        assert quantity in PROBE_QUANTITIES, f"{base}: quantity {quantity!r}"
        comp = np.atleast_1d(g["component"])
        assert np.issubdtype(comp.dtype, np.integer) and comp.size == PROBE_QUANTITIES[quantity]
        assert np.all((comp >= 0) & (comp < a["dim"])), f"{base}: component {comp}"
        assert g["reference"] in PROBE_REFERENCES, f"{base}: reference {g['reference']!r}"
        p = g["particle"]
        assert isinstance(p, (int, np.integer)) and 0 <= p < X.shape[0], f"{base}: particle {p}"
        np.testing.assert_array_equal(np.atleast_1d(g["x0"]), X[p], err_msg=f"{base}: x0")
        time, step = run.ds(f"{base}/time"), run.ds(f"{base}/step")
        n_t = time.shape[0]
        for ds, unit in (("time", "s"), ("step", "1"), ("value", PROBE_UNITS[quantity]),
                         ("reference", PROBE_UNITS[quantity])):
            assert run.ds(f"{base}/{ds}").shape == (n_t,), f"{base}/{ds} shape"
            assert run.units[f"{base}/{ds}"] == unit, f"{base}/{ds} units"
        assert np.issubdtype(step.dtype, np.integer)
        # Every step from 0, up to the last the run completed.
        np.testing.assert_array_equal(step, np.arange(n_t))
        if run.status == "ok":
            assert step[-1] == a["steps"], f"{base}: last step {step[-1]} != {a['steps']}"
        np.testing.assert_allclose(time, step * a["dt"], rtol=0, atol=1e-6 * a["dt"])
        reference = run.ds(f"{base}/reference")
        if g["reference"] == "none":
            assert np.all(np.isnan(reference))
        else:
            assert np.all(np.isfinite(reference)), f"{base}: reference has NaN"


def test_probes_match_the_history(run):
    """At the sampled steps the probe holds the sampled state of its particle."""
    _require_probes(run)
    sampled = run.ds("/history/step")
    for name in _probes(run):
        base = f"/probes/{name}"
        step = run.ds(f"{base}/step")
        at = np.searchsorted(step, sampled)
        keep = (at < step.size) & (step[np.minimum(at, step.size - 1)] == sampled)
        expected = _probe_quantity(run, name)[keep]
        np.testing.assert_array_equal(run.ds(f"{base}/value")[at[keep]], expected,
                                      err_msg=f"{base}/value against /history")


def test_probe_wiggle_measures(run):
    """The total variations and the overshoot of /probes/<name> recomputed from its data."""
    _require_probes(run)
    for name in _probes(run):
        base = f"/probes/{name}"
        g = run.group(base)
        value, reference = run.ds(f"{base}/value"), run.ds(f"{base}/reference")
        tv = np.sum(np.abs(np.diff(value)))
        np.testing.assert_allclose(g["total_variation"], tv, rtol=1e-12, atol=0,
                                   err_msg=f"{base}: total_variation")
        if g["reference"] == "none":
            assert np.isnan(g["reference_total_variation"]) and np.isnan(g["overshoot"])
            continue
        np.testing.assert_allclose(g["reference_total_variation"],
                                   np.sum(np.abs(np.diff(reference))), rtol=1e-12, atol=0,
                                   err_msg=f"{base}: reference_total_variation")
        past = max(value.max() - reference.max(), reference.min() - value.min(), 0.0)
        np.testing.assert_allclose(g["overshoot"], past, rtol=1e-12, atol=0,
                                   err_msg=f"{base}: overshoot")


def dyka_reference(run, x, t, quantity):
    """d'Alembert with images: V is v0 on [3L/4, L], odd about 0, even about L (period 4L)."""
    length, v0 = run.param("L"), run.param("v0")
    rho0, young = run.param("rho0"), run.param("E")
    c = np.sqrt(young / rho0)

    def V(y):
        y = np.mod(y + 2 * length, 4 * length) - 2 * length  # [-2L, 2L)
        sign = np.where(y < 0, -1.0, 1.0)
        y = np.abs(y)
        y = np.where(y > length, 2 * length - y, y)
        return sign * np.where(y >= 0.75 * length, v0, 0.0)

    ahead, behind = V(x + c * t), V(x - c * t)
    if quantity == "velocity":
        return (ahead + behind) / 2
    if quantity == "stress":
        return rho0 * c * (ahead - behind) / 2
    pytest.skip(f"no independent {quantity} reference for dyka_bar")


def andersen_reference(run, y, t, quantity):
    """The small-strain static column under gravity ramped by eq 41."""
    height, rho0, young = run.param("H"), run.param("rho0"), run.param("E")
    g, period = run.param("g"), run.param("T")
    ramp = np.where(t <= period / 2, 0.5 * (np.sin(2 * np.pi * t / period - np.pi / 2) + 1), 1.0)
    load = rho0 * g * ramp
    if quantity == "stress":
        return -load * (height - y)
    return -load / young * (height * y - y * y / 2)


def test_probe_references_by_a_second_implementation(run):
    _require_probes(run)
    benchmark = run.attrs["benchmark"]
    if benchmark not in PROBED:
        pytest.skip(f"no independent probe reference for {benchmark}")
    for name in _probes(run):
        base = f"/probes/{name}"
        g = run.group(base)
        x0 = np.atleast_1d(g["x0"])
        t = run.ds(f"{base}/time")
        # A front passing the particle within rounding of a time level may be taken on
        # either side (Dyka bar); the static column is smooth.
        allowed = 0
        if benchmark == "dyka_bar":
            allowed = 2
            assert g["reference"] == "exact"
            expected = dyka_reference(run, x0[0], t, g["quantity"])
            scale = run.param("rho0") * np.sqrt(run.param("E") / run.param("rho0")) * abs(
                run.param("v0")) if g["quantity"] == "stress" else abs(run.param("v0"))
        else:
            assert g["reference"] == "static"
            expected = andersen_reference(run, x0[1], t, g["quantity"])
            scale = np.max(np.abs(expected), initial=1e-300)
        stored = run.ds(f"{base}/reference")
        close = np.abs(stored - expected) <= 1e-9 * scale
        assert np.count_nonzero(~close) <= allowed, (
            f"{base}/reference differs from the independent solution at steps "
            f"{np.flatnonzero(~close)[:10]}"
        )


# A convergence figure's series label: "<field>, <axis>=<value>, ... (rate r)".
# `<field>[ (<unit>)][, <axis>=<value>...][ (rate r)][ (on top of <series>)]`: the unit when
# the figure shows several fields, the note when an earlier series hides this one.
CONVERGENCE_LABEL = re.compile(
    r"^(?P<field>[a-z_]+)( \([^()]*\))?(?P<axes>(, [a-z_]+=[^,()]+)*)( \(rate [-0-9.na]+\))?"
    r"( \(on top of [^()]*\))?$"
)


def test_field_map_data_matches_the_run_files():
    """Every cell of the reduced TLS matrix's field map of u^h, as written beside the PNG, is a
    map sample of the run its panel names, at its position with its u^h, and the markers are
    that run's data points: the map's data is the run files' numbers, read back with h5py."""
    root = _results_root()
    figures = sorted((root / "ci_tls" / "figures").glob("ci_tls_map_reconstructed_*.csv")) \
        if root is not None else []
    if not figures:
        pytest.skip("no reduced TLS report (make test writes it before this test)")
    samples = {}
    for path in sorted((root / "ci_tls" / "runs").glob("*.h5")):
        with h5py.File(path, "r") as f:
            if f.attrs["dim"] != 2 or f["elements"].attrs["gauss"] != 2:
                continue
            g = f["elements"]
            method = f["matrix"].attrs["method"]
            method = method.decode() if isinstance(method, bytes) else str(method)
            samples[method] = (g["map_x"][()], g["map_reconstructed"][()], g["data_x"][()])
    assert set(samples) == {"tls_fixed", "tls_fitted"}, sorted(samples)
    checked = 0
    for data in figures:
        lines = data.read_text().splitlines()
        header = lines[0].split(",")
        assert header[:2] == ["panel", "role"] and header[4:6] == ["width", "height"], header
        rows = {}
        for row in lines[1:]:
            panel, role, x, y, width, height, value = row.rsplit(",", 6)
            method = re.match(r'^"?method=([a-z_]+)', panel)[1]
            rows.setdefault((method, role), []).append((x, y, width, height, value))
        for method, (map_x, uh, data_x) in samples.items():
            cells = rows[(method, "cell")]
            assert len(cells) == len(uh), f"{data.name}: {method} has {len(cells)} cells"
            got = np.array([[float(c[0]), float(c[1]), float(c[4])] for c in cells])
            np.testing.assert_array_equal(got[:, :2], map_x, err_msg=f"{data.name}: {method}")
            np.testing.assert_array_equal(got[:, 2], uh, err_msg=f"{data.name}: {method}")
            # The cells tile each element: as wide as the spacing of the samples.
            width = float(cells[0][2])
            np.testing.assert_allclose(width, np.min(np.diff(np.unique(map_x[:, 0]))), rtol=1e-12)
            markers = np.array([[float(m[0]), float(m[1])] for m in rows[(method, "marker")]])
            np.testing.assert_array_equal(markers, data_x, err_msg=f"{data.name}: {method}")
            checked += len(cells)
    assert checked >= 2 * 25, f"only {checked} cells checked"


def test_convergence_figure_data_matches_the_run_files():
    """Every measured point of the reduced bar's convergence figure, as written beside the PNG,
    is a finished run's final error in that field and norm at its h: the figure's data is the
    run files' numbers, read back with h5py alone."""
    root = _results_root()
    if root is None or not (root / "ci_bar" / "figures").is_dir():
        pytest.skip("no reduced bar report (make test writes it before this test)")
    runs = []
    for path in sorted((root / "ci_bar" / "runs").glob("*.h5")):
        with h5py.File(path, "r") as f:
            axes = {
                k: (v.decode() if isinstance(v, bytes) else str(v))
                for k, v in f["matrix"].attrs.items()
            }
            norms = {k: float(v) for k, v in f["errors/norms"].attrs.items()}
            runs.append((float(f.attrs["h"]), str(f.attrs["status"]), axes, norms))
    figures = sorted((root / "ci_bar" / "figures").glob("*.csv"))
    assert figures, "the reduced bar's report wrote no figure data"
    checked = 0
    for data in figures:
        rows = list(csv.reader(data.read_text().splitlines()))
        header = rows[0]
        assert header[:2] == ["series", "role"], f"{data.name}: header {header}"
        norm = header[3].split()[0]
        for label, role, x, y in rows[1:]:
            if role != "marker":
                continue
            m = CONVERGENCE_LABEL.match(label)
            assert m, f"{data.name}: unexpected series label {label!r}"
            field = m["field"]
            wanted = dict(a.split("=", 1) for a in m["axes"].split(", ")[1:])
            matches = [
                norms for h, status, axes, norms in runs
                if status == "ok" and abs(h - float(x)) <= 1e-12 * h
                and all(axes.get(k) == v for k, v in wanted.items())
            ]
            assert len(matches) == 1, f"{data.name}: {len(matches)} runs for {label!r} at h = {x}"
            assert matches[0][f"{norm}_{field}"] == float(y), f"{data.name}: {label!r} at h = {x}"
            checked += 1
    assert checked >= 30, f"only {checked} points checked"
