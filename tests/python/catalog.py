"""mpmlab's catalogues as the binary lists them (`mpmlab list-methods --json`,
`mpmlab list-benchmarks --json`), so that the layout tests follow the presets, parts and
benchmarks the code has instead of copies of them. $MPMLAB_BIN names the binary (`make test`
sets it); without it, the release build of this checkout."""

import json
import os
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("MPMLAB_BIN", ROOT / "target" / "release" / "mpmlab"))


def _listing(command):
    out = subprocess.run([str(BIN), command, "--json"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


METHODS = _listing("list-methods")
BENCHMARK_LIST = _listing("list-benchmarks")

PRESETS = {p["name"]: p for p in METHODS["presets"]}
# Solvers that are not MPM (their run files have one point per element, no mapping).
REFERENCE_METHODS = tuple(m["name"] for m in METHODS["reference"])
BENCHMARK_KINDS = {b["name"]: b["kind"] for b in BENCHMARK_LIST}

# The parts whose mappings conserve mass and momentum to round-off: shape functions that are a
# partition of unity to the last bit, with the lumped Shepard sums, the consistent mass matrix
# or TLS, which prescribes each element's mass and momentum.
CONSERVING_SHAPES = (
    "linear",
    "quadratic_bspline",
    "cubic_bspline",
    "dual_domain",
    "dual_domain_cells",
)
CONSERVING_TRANSFERS = ("shepard", "consistent_mass", "tls", "tls_lumped")

# Per shape part, the degree of its DOF lattice: cells + degree DOFs per axis, at the Greville
# abscissae of that degree (1: the grid nodes).
DOF_DEGREES = {p["name"]: p["dof_degree"] for p in METHODS["parts"]["shape"]}


def method_parts(method, param):
    """The (shape, transfer) names of a run of `method`: the preset's, or the run's `shape`
    and `transfer` parameters where it sets them. `param(key)` returns a run parameter or
    None."""
    preset = PRESETS.get(method)
    shape = param("shape") or (preset and preset["shape"])
    transfer = param("transfer") or (preset and preset["transfer"])
    return shape, transfer


def conserves(method, param):
    shape, transfer = method_parts(method, param)
    return shape in CONSERVING_SHAPES and transfer in CONSERVING_TRANSFERS
