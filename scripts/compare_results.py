"""Compares two results directories (`mpmlab run --out A` and `--out B`) bit for bit.

    python scripts/compare_results.py A B

For every experiment directory of A (one with an experiment.yaml) B must have the same
experiment.yaml, the same run files and no temporary files left, and every pair of run files
must hold the same groups, datasets and attributes: every dataset with the same dtype, shape
and bytes, every attribute equal. Excluded, because they record time: the root attributes
`wall_seconds` and `step_seconds` of each run file (and timings.csv and costs.md, which are not compared). B must have the same
XDMF descriptions (<run_id>.xdmf), byte for byte. The report files
(summary.csv, rates.csv, report.md, figures/*.png) must be byte-identical where A has them.
Exits 1 listing the differences.
"""

import sys
from pathlib import Path

import h5py
import numpy as np

TIME_ATTRS = {("/", "wall_seconds"), ("/", "step_seconds")}


def value_bytes(value):
    """A comparable form of a dataset's or attribute's value: its dtype, shape and bytes."""
    array = np.asarray(value)
    if array.dtype.kind == "O":  # variable-length strings
        return (array.shape, [str(v) for v in array.ravel()])
    return (array.dtype.str, array.shape, array.tobytes())


def contents(path):
    """{(object path, kind, name): comparable value} for every dataset and attribute."""
    items = {}
    with h5py.File(path, "r") as f:

        def add(name, obj):
            key = "/" + name if name else "/"
            if isinstance(obj, h5py.Dataset):
                items[(key, "dataset", "")] = value_bytes(obj[()])
            else:
                items[(key, "group", "")] = None
            for attr, value in obj.attrs.items():
                if (key, attr) not in TIME_ATTRS:
                    items[(key, "attr", attr)] = value_bytes(value)

        add("", f)
        f.visititems(add)
    return items


def common_runs_files(a, b, pattern, what, problems):
    """The names matching `pattern` in both runs/ directories; a problem when the sets differ."""
    names_a = {p.name for p in (a / "runs").glob(pattern)}
    names_b = {p.name for p in (b / "runs").glob(pattern)}
    if names_a != names_b:
        only_a, only_b = sorted(names_a - names_b), sorted(names_b - names_a)
        problems.append(f"{a.name}: {what} differ: only in A {only_a}, only in B {only_b}")
    return sorted(names_a & names_b)


def compare_experiment(a, b, problems, counts):
    name = a.name
    if not (b / "experiment.yaml").is_file():
        problems.append(f"{name}: no experiment.yaml in {b}")
        return
    if (a / "experiment.yaml").read_bytes() != (b / "experiment.yaml").read_bytes():
        problems.append(f"{name}: experiment.yaml differs")
    for d in (a, b):
        # Hidden files but the record of the experiment file (`runner::check_copy`) are what
        # a write or a lock left behind.
        leftovers = [p.name for p in (d / "runs").glob(".*") if p.name != ".experiment-source"]
        if leftovers:
            problems.append(f"{d}: temporary files left: {leftovers}")
    for run in common_runs_files(a, b, "*.h5", "run files", problems):
        ca, cb = contents(a / "runs" / run), contents(b / "runs" / run)
        if ca.keys() != cb.keys():
            diff = sorted(set(ca) ^ set(cb))
            problems.append(f"{name}/{run}: objects or attributes differ: {diff[:5]}")
        for key in sorted(set(ca) & set(cb)):
            if ca[key] != cb[key]:
                problems.append(f"{name}/{run}: {key[1]} {key[0]} {key[2]} differs")
        counts["runs"] += 1
        counts["datasets"] += sum(1 for k in ca if k[1] == "dataset")
        counts["attributes"] += sum(1 for k in ca if k[1] == "attr")
    for xdmf in common_runs_files(a, b, "*.xdmf", "XDMF files", problems):
        if (a / "runs" / xdmf).read_bytes() != (b / "runs" / xdmf).read_bytes():
            problems.append(f"{name}/{xdmf} differs")
        else:
            counts["descriptions"] += 1
    for report in ["summary.csv", "rates.csv", "report.md"] + sorted(
        str(p.relative_to(a)) for p in a.glob("figures/*.png")
    ):
        if not (a / report).exists():
            continue
        if not (b / report).exists():
            problems.append(f"{name}: {report} missing in B")
        elif (a / report).read_bytes() != (b / report).read_bytes():
            problems.append(f"{name}: {report} differs")
        else:
            counts["report files"] += 1


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    a, b = Path(argv[1]), Path(argv[2])
    experiments = sorted(p.parent for p in a.glob("*/experiment.yaml"))
    if not experiments:
        sys.exit(f"{a}: no experiment directories")
    problems = []
    counts = {"runs": 0, "datasets": 0, "attributes": 0, "descriptions": 0, "report files": 0}
    for experiment in experiments:
        compare_experiment(experiment, b / experiment.name, problems, counts)
    for problem in problems[:50]:
        print(f"DIFFERENT: {problem}")
    print(
        f"{len(experiments)} experiments, {counts['runs']} run files: {counts['datasets']} "
        f"datasets and {counts['attributes']} attributes compared bit for bit (excluded: the "
        f"root attributes wall_seconds and step_seconds), {counts['descriptions']} XDMF "
        f"descriptions and "
        f"{counts['report files']} report files byte for byte: "
        + ("identical" if not problems else f"{len(problems)} differences")
    )
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
