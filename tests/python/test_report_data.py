"""The data files beside the figures of `mpmlab report` against the run files.
"""

import csv
import re

import h5py
import numpy as np
import pytest

from layout import _results_root


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
