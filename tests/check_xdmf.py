#!/usr/bin/env python3
"""Independent check of the ParaView output written by examples/xdmf_selftest.rs.

Usage: check_xdmf.py OUT_DIR [--steps 1,2,3,4]

Reads OUT_DIR/fields.xdmf with xml.etree and every dataset it references with h5py, and checks
them against the synthetic square the self test writes (see the example's header): shapes and
types as declared, connectivity in range, counter-clockwise triangles of positive area tiling
the sheared square, particle ids matching positions, and every field equal to its function of
position and time. With meshio installed, also reads the series with meshio's
TimeSeriesReader and each frame on its own with meshio.read, and checks the same. Prints what
it checked; exits 1 listing every failure.
"""

import argparse
import math
import os
import sys
import tempfile
import xml.etree.ElementTree as ET

import h5py
import numpy as np

try:
    import meshio
    from meshio.xdmf import TimeSeriesReader
except ImportError:  # meshio is optional; h5py is not
    meshio = None

RTOL = 1e-12
ATOL = 1e-13
NUMPY_TYPE = {
    ("Float", "8"): np.float64,
    ("Float", "4"): np.float32,
    ("Int", "8"): np.int64,
    ("Int", "4"): np.int32,
    ("UInt", "8"): np.uint64,
    ("UInt", "4"): np.uint32,
}
FIELD_KINDS = {
    "gid": ("Scalar", 1),
    "pressure": ("Scalar", 1),
    "level": ("Scalar", 1),
    "velocity": ("Vector", 3),
    "flow": ("Vector", 3),
    "stress": ("Tensor", 9),
}

failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
    return ok


def expected_fields(points, t):
    """The self test's fields as functions of current position and time."""
    x, y = points[:, 0], points[:, 1]
    zero = np.zeros_like(x)
    return {
        "pressure": np.sin(3.0 * x) + y * y,
        "level": t + x,
        "velocity": np.stack([x * y, x - 2.0 * y, zero], axis=1),
        "flow": np.stack([np.cos(x), t * y, zero], axis=1),
        "stress": np.stack(
            [x, x * y, zero, x * y, y, zero, zero, zero, x + y], axis=1
        ),
    }


def lattice_position(step, k):
    """Position of lattice point k of frame `step` (x = X + 0.1 s Y, y = (1 + 0.05 s) Y)."""
    n = 3 + step
    i, j = k % (n + 1), k // (n + 1)
    x0, y0 = i / n, j / n
    return np.stack([x0 + 0.1 * step * y0, (1.0 + 0.05 * step) * y0], axis=1)


def read_item(item, xdmf_dir, where):
    """Reads an HDF DataItem, checking its declared type and dimensions against the dataset."""
    if not check(item.get("Format") == "HDF", f"{where}: Format is {item.get('Format')}"):
        return None
    ref = (item.text or "").strip()
    file_name, _, dataset = ref.partition(":")
    path = os.path.join(xdmf_dir, file_name)
    if not check(os.path.isfile(path), f"{where}: {path} does not exist"):
        return None
    with h5py.File(path, "r") as f:
        if not check(dataset in f, f"{where}: {path} has no dataset {dataset}"):
            return None
        data = f[dataset][()]
    dims = tuple(int(d) for d in item.get("Dimensions").split())
    check(data.shape == dims, f"{where}: shape {data.shape}, declared {dims}")
    key = (item.get("NumberType"), item.get("Precision"))
    want = NUMPY_TYPE.get(key)
    check(
        want is not None and data.dtype == want,
        f"{where}: dtype {data.dtype}, declared {key}",
    )
    return data


def check_mesh(where, step, points, tris):
    n = 3 + step
    check(points.shape == ((n + 1) ** 2, 2), f"{where}: geometry shape {points.shape}")
    check(tris.shape == (2 * n * n, 3), f"{where}: connectivity shape {tris.shape}")
    if tris.size == 0 or points.size == 0:
        return
    if not check(
        tris.min() >= 0 and tris.max() < len(points),
        f"{where}: connectivity outside 0..{len(points)}",
    ):
        return
    a, b, c = (points[tris[:, k]] for k in range(3))
    area = 0.5 * (
        (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1])
        - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    )
    check(
        area.min() > 0.0,
        f"{where}: {int((area <= 0).sum())} triangles not counter-clockwise",
    )
    # Positive areas summing to the square's area: the triangles tile it without overlap.
    check(
        math.isclose(area.sum(), 1.0 + 0.05 * step, rel_tol=1e-12),
        f"{where}: triangle areas sum to {area.sum()}, expected {1.0 + 0.05 * step}",
    )
    check(
        len(np.unique(tris)) == len(points),
        f"{where}: {len(points) - len(np.unique(tris))} points in no triangle",
    )


def check_values(where, points, t, data):
    """`data`: name -> array as read; compares every field with its synthetic value."""
    expected = expected_fields(points, t)
    for name, want in expected.items():
        got = data.get(name)
        if not check(got is not None, f"{where}: no field {name}"):
            continue
        if not check(got.shape == want.shape, f"{where}: {name} shape {got.shape}"):
            continue
        bad = ~np.isclose(got, want, rtol=RTOL, atol=ATOL)
        check(
            not bad.any(),
            f"{where}: {name} differs at {int(bad.sum())} values, e.g. {got[bad][:3].tolist()} "
            f"vs {want[bad][:3].tolist()}",
        )


def check_frame(xdmf_dir, grid, step, t):
    where = f"frame {step}"
    topo = grid.find("Topology")
    geom = grid.find("Geometry")
    if not check(topo is not None and geom is not None, f"{where}: no topology or geometry"):
        return None
    check(topo.get("TopologyType") == "Triangle", f"{where}: topology {topo.attrib}")
    check(geom.get("GeometryType") == "XY", f"{where}: geometry {geom.attrib}")
    tris = read_item(topo.find("DataItem"), xdmf_dir, f"{where} connectivity")
    points = read_item(geom.find("DataItem"), xdmf_dir, f"{where} geometry")
    if tris is None or points is None:
        return None
    check(
        int(topo.get("NumberOfElements")) == len(tris),
        f"{where}: NumberOfElements {topo.get('NumberOfElements')} for {len(tris)} rows",
    )
    check_mesh(where, step, points, tris)

    data = {}
    for attr in grid.findall("Attribute"):
        name = attr.get("Name")
        kind = FIELD_KINDS.get(name)
        if not check(kind is not None, f"{where}: unexpected attribute {name}"):
            continue
        check(attr.get("Center") == "Node", f"{where}: {name} centred {attr.get('Center')}")
        check(
            attr.get("AttributeType") == kind[0],
            f"{where}: {name} is {attr.get('AttributeType')}, expected {kind[0]}",
        )
        values = read_item(attr.find("DataItem"), xdmf_dir, f"{where} {name}")
        if values is None:
            continue
        shape = (len(points),) if kind[1] == 1 else (len(points), kind[1])
        check(values.shape == shape, f"{where}: {name} shape {values.shape}, expected {shape}")
        data[name] = values
    check(set(data) == set(FIELD_KINDS), f"{where}: attributes {sorted(data)}")
    check_values(where, points, t, data)

    gid = data.get("gid")
    if gid is not None and gid.shape == (len(points),):
        check(len(np.unique(gid)) == len(gid), f"{where}: repeated particle ids")
        k = (gid - 1000) // 7
        check(
            bool(((gid - 1000) % 7 == 0).all() and (k >= 0).all()),
            f"{where}: ids not of the form 1000 + 7k",
        )
        check(
            np.allclose(points, lattice_position(step, k), rtol=RTOL, atol=ATOL),
            f"{where}: positions do not match their particle ids",
        )

    file_name = topo.find("DataItem").text.strip().partition(":")[0]
    with h5py.File(os.path.join(xdmf_dir, file_name), "r") as f:
        check(f.attrs.get("format") == "pfem-mpi fields", f"{where}: format {f.attrs.get('format')}")
        check(int(f.attrs.get("format_version", 0)) == 1, f"{where}: format_version")
        check(int(f.attrs.get("step", -1)) == step, f"{where}: step attribute {f.attrs.get('step')}")
        check(float(f.attrs.get("time", math.nan)) == t, f"{where}: time attribute {f.attrs.get('time')}")
    return points, tris, data


def check_with_meshio(xdmf_path, frames):
    """frames: list of (step, time, points, tris, data) as read with h5py."""
    with TimeSeriesReader(xdmf_path) as reader:
        points, cells = reader.read_points_cells()
        step0, _, points0, tris0, _ = frames[0]
        # meshio's series reader takes the mesh of the first frame for all frames.
        check(np.array_equal(points, points0), "meshio series: points of the first frame")
        check(
            len(cells) == 1 and cells[0].type == "triangle" and np.array_equal(cells[0].data, tris0),
            "meshio series: triangles of the first frame",
        )
        check(reader.num_steps == len(frames), f"meshio series: {reader.num_steps} steps")
        for k, (step, t, pts, _, data) in enumerate(frames):
            tk, point_data, _ = reader.read_data(k)
            check(tk == t, f"meshio series frame {step}: time {tk}, expected {t}")
            check(set(point_data) == set(FIELD_KINDS), f"meshio series frame {step}: {sorted(point_data)}")
            for name, values in point_data.items():
                check(
                    name in data and np.array_equal(values, data[name]),
                    f"meshio series frame {step}: {name} differs from h5py",
                )
            check_values(f"meshio series frame {step}", pts, t, point_data)

    # Each frame on its own: the grid without its time, in a file next to the series so that
    # the relative data paths resolve.
    xdmf_dir = os.path.dirname(os.path.abspath(xdmf_path))
    root = ET.parse(xdmf_path).getroot()
    for grid in root.iter("Grid"):
        if grid.get("GridType") != "Uniform":
            continue
        step = int(grid.get("Name").removeprefix("step_"))
        t = float(grid.find("Time").get("Value"))
        single = ET.Element("Xdmf", Version="3.0")
        domain = ET.SubElement(single, "Domain")
        copy = ET.SubElement(domain, "Grid", Name=grid.get("Name"), GridType="Uniform")
        for child in grid:
            if child.tag != "Time":
                copy.append(child)
        fd, path = tempfile.mkstemp(suffix=".xdmf", dir=xdmf_dir)
        os.close(fd)
        try:
            ET.ElementTree(single).write(path)
            mesh = meshio.read(path)
        finally:
            os.remove(path)
        where = f"meshio frame {step}"
        tris = mesh.cells_dict.get("triangle")
        if not check(tris is not None, f"{where}: no triangles"):
            continue
        check_mesh(where, step, mesh.points, tris)
        check_values(where, mesh.points, t, mesh.point_data)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("out_dir")
    parser.add_argument("--steps", default="1,2,3,4")
    args = parser.parse_args()
    steps = [int(s) for s in args.steps.split(",")]
    xdmf_path = os.path.join(args.out_dir, "fields.xdmf")
    xdmf_dir = os.path.dirname(os.path.abspath(xdmf_path))

    root = ET.parse(xdmf_path).getroot()
    check(root.tag == "Xdmf" and root.get("Version", "").startswith("3"), f"root {root.tag} {root.attrib}")
    domains = root.findall("Domain")
    collections = [g for g in domains[0].findall("Grid")] if len(domains) == 1 else []
    check(
        len(collections) == 1
        and collections[0].get("GridType") == "Collection"
        and collections[0].get("CollectionType") == "Temporal",
        "one temporal collection in one domain",
    )
    grids = collections[0].findall("Grid") if collections else []
    listed = [int(g.get("Name", "").removeprefix("step_")) for g in grids]
    check(listed == steps, f"frames of steps {listed}, expected {steps}")
    check(not os.path.exists(xdmf_path + ".tmp"), "temporary series file left behind")

    frames = []
    for grid, step in zip(grids, listed):
        check(grid.get("GridType") == "Uniform", f"frame {step}: {grid.attrib}")
        time = grid.find("Time")
        t = float(time.get("Value")) if time is not None else math.nan
        check(t == 0.1 * step, f"frame {step}: time {t}, expected {0.1 * step}")
        read = check_frame(xdmf_dir, grid, step, t)
        if read is not None:
            frames.append((step, t, *read))

    checked = f"{len(frames)} frames with h5py"
    if meshio is None:
        checked += "; meshio not installed, meshio checks skipped"
    elif frames and not failures:
        check_with_meshio(xdmf_path, frames)
        checked += f" and meshio {meshio.__version__}"
    if failures:
        print(f"{xdmf_path}: {len(failures)} failures:", file=sys.stderr)
        for f in failures:
            print(f"  {f}", file=sys.stderr)
        sys.exit(1)
    print(f"{xdmf_path}: OK ({checked})")


if __name__ == "__main__":
    main()
