"""Opens the XDMF descriptions beside the run files under $MPMLAB_RESULTS with VTK's own XDMF
reader (vtkXdmfReader, ParaView's "XDMF Reader") and checks what it reads against the run files
read with h5py: every run file with a particle history has <run_id>.xdmf beside it and no other
has one; the reader reports no warning or error, gives one time step per sample at the sample
times, one vertex per particle at the sampled positions (z = 0, and y = 0 in 1D), and every
per-sample dataset of /history and /errors, at every sample of every such run file, 1D and 2D,
all bit for bit.

The run files are those of the layout tests (layout.py) (`make test` runs the reduced matrices first).
"""

import h5py
import numpy as np
import pytest
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline
from vtkmodules.vtkIOXdmf2 import vtkXdmfReader

from layout import ENV, RUN_FILES, _file_id

# Point array name -> run file dataset: the whole (samples x particles x ...) histories.
FIELDS = {
    "position": "/history/x",
    "velocity": "/history/v",
    "stress": "/history/stress",
    "density": "/history/density",
    "volume": "/errors/volume",
    **{f"{f}_error": f"/errors/{f}" for f in ("displacement", "velocity", "stress", "density")},
}


def _has_history(path):
    with h5py.File(path, "r") as f:
        return "history" in f and f["history/time"].size > 0 and f["particles/X"].shape[0] > 0


DESCRIBED = [p for p in RUN_FILES if _has_history(p)]


def _dim(path):
    with h5py.File(path, "r") as f:
        return int(f.attrs["dim"])


def test_descriptions_beside_the_run_files():
    dims = {_dim(p) for p in DESCRIBED}
    assert {1, 2} <= dims, f"the runs with a particle history under {ENV} have dims {dims}"
    for path in RUN_FILES:
        xdmf = path.with_suffix(".xdmf")
        if path in DESCRIBED:
            assert xdmf.is_file(), f"{_file_id(path)} has no {xdmf.name}"
        else:
            assert not xdmf.exists(), f"{_file_id(path)} has no particle history but an XDMF"
    for path in {p.parent for p in RUN_FILES}:
        for xdmf in path.glob("*.xdmf"):
            assert xdmf.with_suffix(".h5").is_file(), f"{xdmf} has no run file"


@pytest.fixture
def vtk_messages():
    """What VTK would print (warnings and errors), collected instead."""
    previous = vtkOutputWindow.GetInstance()
    log = vtkStringOutputWindow()
    vtkOutputWindow.SetInstance(log)
    yield log
    vtkOutputWindow.SetInstance(previous)


def _as_rows(array, n_p):
    """A run file's (particles x ...) sample as VTK's reader gives it: one row per particle,
    a 2-vector padded to 3 components with a zero, a tensor flattened row by row."""
    rows = array.reshape(n_p, -1)
    if rows.shape[1] == 2 and array.ndim == 2:
        rows = np.hstack([rows, np.zeros((n_p, 1))])
    return rows[:, 0] if rows.shape[1] == 1 else rows


@pytest.mark.parametrize("path", DESCRIBED, ids=[_file_id(p) for p in DESCRIBED])
def test_vtk_reads_the_history(path, vtk_messages):
    dim = _dim(path)
    reader = vtkXdmfReader()
    reader.SetFileName(str(path.with_suffix(".xdmf")))
    reader.UpdateInformation()
    times = reader.GetOutputInformation(0).Get(vtkStreamingDemandDrivenPipeline.TIME_STEPS())
    with h5py.File(path, "r") as f:
        sample_times = f["history/time"][()]
        np.testing.assert_array_equal(np.asarray(times), sample_times, err_msg="time steps")
        n_p = f["particles/X"].shape[0]
        for sample in range(len(sample_times)):
            reader.UpdateTimeStep(sample_times[sample])
            grid = reader.GetOutputDataObject(0)
            assert grid.GetNumberOfPoints() == n_p and grid.GetNumberOfCells() == n_p
            points = vtk_to_numpy(grid.GetPoints().GetData())
            x = f["history/x"][sample]
            np.testing.assert_array_equal(points[:, :dim], x, err_msg=f"points at {sample}")
            np.testing.assert_array_equal(points[:, dim:], 0.0)
            data = grid.GetPointData()
            names = {data.GetArrayName(k) for k in range(data.GetNumberOfArrays())}
            assert names == set(FIELDS), f"point arrays {sorted(names)}"
            for name, dataset in FIELDS.items():
                np.testing.assert_array_equal(
                    vtk_to_numpy(data.GetArray(name)),
                    _as_rows(f[dataset][sample], n_p),
                    err_msg=f"{_file_id(path)}: {name} at sample {sample}",
                )
    assert vtk_messages.GetOutput() == "", vtk_messages.GetOutput()
