"""What the HDF5 layout holds (names, units, tolerances), where the run files are
($MPMLAB_RESULTS), and `Run`, one run file read into memory: shared by the layout tests.
"""

import os
import re
from pathlib import Path

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
