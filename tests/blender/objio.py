"""Mesh and tangent-table I/O shared by sgbake's Blender oracle test and benchmarks.

This module is imported both inside Blender (by make_tangent_cases.py and by
bench/tangents_vs_blender.py in its Blender half) and by plain python3 (compare_tangents.py).
The functions that read Blender meshes and write files use numpy (always there inside Blender)
and import it themselves; read_tangent_csv is plain Python, so the comparator runs on any
python3. The module never imports bpy: the mesh readers touch only the mesh they are given.

File formats
------------
OBJ (written by write_obj, not by Blender's exporter, so that we control every byte):
    v x y z            one per mesh vertex, in vertex order
    vt u v             one per face corner ("loop"), in corner order
    vn x y z           one per face corner, in corner order
    f v/vt/vn ...      one per face, in face order, its corners in corner order
    s 0 | s 1          before each run of flat / smooth faces, only when the arrays say which
                       faces are smooth ("smooth")
Every float is written with '%.9g', which round-trips a float32 exactly, so sgbake reads the
very bits Blender computed with.

Tangent CSV (the sgbake CLI's `tangents` output, and the Blender reference):
    face,corner,tx,ty,tz,sign
one row per face corner in face order and each face's corner order; `corner` is the index of
the corner within its face (0-based); sign is +1 or -1.
"""

import math
import os
import subprocess

CSV_HEADER = "face,corner,tx,ty,tz,sign"


def run_blender(blender, script, args, blender_options=(), **kwargs):
    """Runs `blender -b --factory-startup [OPTIONS] --python-exit-code 1 --python SCRIPT -- ARGS`.

    A system Blender (Debian's) finds its Python home through the first `python3.X` on PATH.
    Under pyenv or a virtualenv that is a different Python whose site-packages lack numpy
    (and whose stdlib may not even match Blender's libpython), so the scripts would fail on
    `import numpy`. Putting Blender's own directory first on PATH makes it find the Python it
    was built against. blender_options (e.g. ["-t", "1"]) come before the script, since
    Blender applies its options in order. Extra keyword arguments go to subprocess.run;
    returns its CompletedProcess.
    """
    env = dict(os.environ)
    blender_dir = os.path.dirname(os.path.realpath(blender))
    env["PATH"] = blender_dir + os.pathsep + env.get("PATH", "")
    cmd = ([blender, "-b", "--factory-startup"] + list(blender_options)
           + ["--python-exit-code", "1", "--python", script, "--"] + list(args))
    return subprocess.run(cmd, env=env, check=False, **kwargs)


def run_blender_result(blender, script, args, tag):
    """Runs SCRIPT in Blender (run_blender) and returns the JSON it printed after `tag`, or
    None when it failed (its output shown)."""
    import json
    proc = run_blender(blender, script, args, capture_output=True, text=True)
    for line in proc.stdout.splitlines():
        if proc.returncode == 0 and line.startswith(tag):
            return json.loads(line[len(tag):])
    print(f"error: Blender {' '.join(args[:1])} failed ({proc.returncode})\n"
          f"{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    return None


def run_blender_half(blender, script, args, timeout, tail=3000):
    """Runs SCRIPT in Blender (run_blender) with ARGS, at most `timeout` seconds; returns
    whether it exited with 0. When it did not, prints "error: Blender (ARGS[0]) exited with N"
    and the last `tail` characters of its standard output and of its standard error."""
    proc = run_blender(blender, script, args, capture_output=True, text=True, timeout=timeout)
    if proc.returncode != 0:
        print(f"error: Blender ({' '.join(args[:1])}) exited with {proc.returncode}\n"
              f"{proc.stdout[-tail:]}\n{proc.stderr[-tail:]}")
    return proc.returncode == 0


def run_script(blender_main, main):
    """The entry point of a script that is both the driver (plain python3) and, re-run by
    run_blender, the Blender half: inside Blender (bpy importable) calls blender_main with the
    arguments after "--", elsewhere exits with main()'s status."""
    import importlib.util
    import sys
    if importlib.util.find_spec("bpy") is not None:
        blender_main(sys.argv[sys.argv.index("--") + 1:])
    else:
        sys.exit(main())


def mesh_arrays(me):
    """Returns the per-vertex and per-corner arrays of a Blender mesh as numpy arrays.

    The caller must have run `me.calc_normals_split()` (for the corner normals) and, to get
    tangents, `me.calc_tangents()`; this function only reads.

    Returns a dict with
      positions  (V, 3) float32   vertex positions (object space)
      face_size  (F,)   int64     number of corners of each face
      corner_vertex (C,) int64    vertex of each corner
      normals    (C, 3) float32   split normal of each corner
      uvs        (C, 2) float32   active UV map of each corner
    """
    import numpy as np
    nv, nc, nf = len(me.vertices), len(me.loops), len(me.polygons)
    positions = np.empty(nv * 3, np.float32)
    me.vertices.foreach_get("co", positions)
    face_size = np.empty(nf, np.int32)
    me.polygons.foreach_get("loop_total", face_size)
    face_start = np.empty(nf, np.int32)
    me.polygons.foreach_get("loop_start", face_start)
    corner_vertex = np.empty(nc, np.int32)
    me.loops.foreach_get("vertex_index", corner_vertex)
    normals = np.empty(nc * 3, np.float32)
    me.loops.foreach_get("normal", normals)
    uvs = np.empty(nc * 2, np.float32)
    me.uv_layers.active.data.foreach_get("uv", uvs)
    # Blender stores a polygon's loops contiguously and, for meshes built by its own operators,
    # in polygon order. The OBJ writer relies on that, so check it rather than assume it.
    expected_start = np.concatenate(([0], np.cumsum(face_size)[:-1])) if nf else face_start
    if not np.array_equal(face_start, expected_start):
        raise RuntimeError("mesh loops are not stored in polygon order")
    return {
        "positions": positions.reshape(-1, 3),
        "face_size": face_size.astype(np.int64),
        "corner_vertex": corner_vertex.astype(np.int64),
        "normals": normals.reshape(-1, 3),
        "uvs": uvs.reshape(-1, 2),
    }


def mesh_tangents(me):
    """Returns (tangents (C, 3) float32, signs (C,) float32) after `me.calc_tangents()`."""
    import numpy as np
    nc = len(me.loops)
    tangents = np.empty(nc * 3, np.float32)
    me.loops.foreach_get("tangent", tangents)
    signs = np.empty(nc, np.float32)
    me.loops.foreach_get("bitangent_sign", signs)
    return tangents.reshape(-1, 3), signs


def _format_rows(prefix, values):
    """Formats each row of a float array as `prefix v0 v1 ...` with '%.9g' per value."""
    import numpy as np
    values = np.asarray(values, dtype=np.float64)  # exact for float32 input
    fmt = prefix + " " + " ".join(["%.9g"] * values.shape[1])
    return [fmt % tuple(row) for row in values.tolist()]


def write_obj(path, arrays, comment=None, normals=True):
    """Writes the arrays returned by mesh_arrays() as an OBJ file (see the module docstring);
    with normals=False, without `vn` (the reader then computes the normals)."""
    import numpy as np
    nc = len(arrays["corner_vertex"])
    lines = []
    if comment:
        lines.append("# " + comment)
    lines += _format_rows("v", arrays["positions"])
    lines += _format_rows("vt", arrays["uvs"])
    if normals:
        lines += _format_rows("vn", arrays["normals"])
    # One "v/vt/vn" (or "v/vt") token per corner (all indices 1-based), then one line per face.
    corner_index = np.arange(1, nc + 1)
    form = "{v}/{c}/{c}" if normals else "{v}/{c}"
    tokens = [form.format(v=v, c=c) for v, c in zip((arrays["corner_vertex"] + 1).tolist(),
                                                      corner_index.tolist())]
    # Blender's smooth flags, when given ("smooth" (F,) bool): `s 1` / `s 0` before each run of
    # smooth / flat faces, as Blender's exporter writes them.
    smooth = arrays.get("smooth")
    state = None
    start = 0
    for f, size in enumerate(arrays["face_size"].tolist()):
        if smooth is not None and bool(smooth[f]) != state:
            state = bool(smooth[f])
            lines.append("s 1" if state else "s 0")
        lines.append("f " + " ".join(tokens[start:start + size]))
        start += size
    with open(path, "w", encoding="ascii", newline="\n") as f:
        f.write("\n".join(lines))
        f.write("\n")


def corner_ids(face_size):
    """Returns (face index, corner-within-face index) of every corner, both (C,) int64."""
    import numpy as np
    face_size = np.asarray(face_size, dtype=np.int64)
    face = np.repeat(np.arange(len(face_size)), face_size)
    first = np.concatenate(([0], np.cumsum(face_size)[:-1])) if len(face_size) else face_size
    corner = np.arange(int(face_size.sum())) - np.repeat(first, face_size)
    return face, corner


def write_tangent_csv(path, face_size, tangents, signs):
    """Writes a tangent table (see the module docstring)."""
    import numpy as np
    face, corner = corner_ids(face_size)
    tangents = np.asarray(tangents, dtype=np.float64)
    signs = np.asarray(signs, dtype=np.float64)
    rows = ["%d,%d,%.9g,%.9g,%.9g,%d" % (f, c, t[0], t[1], t[2], 1 if s >= 0 else -1)
            for f, c, t, s in zip(face.tolist(), corner.tolist(), tangents.tolist(),
                                  signs.tolist())]
    with open(path, "w", encoding="ascii", newline="\n") as f:
        f.write(CSV_HEADER + "\n")
        f.write("\n".join(rows))
        f.write("\n")


def read_tangent_csv(path):
    """Reads a tangent table with plain Python (no numpy needed).

    Returns a list of rows (face, corner, (tx, ty, tz), sign) with ints for face and corner.
    Raises ValueError with a message naming the file and line when the table is malformed.
    """
    rows = []
    with open(path, "r", encoding="ascii", errors="replace") as f:
        header = f.readline().strip()
        if header != CSV_HEADER:
            raise ValueError(f"{path}:1: header is {header!r}, expected {CSV_HEADER!r}")
        for line_no, line in enumerate(f, start=2):
            fields = line.strip().split(",")
            if fields == [""]:
                continue  # tolerate blank lines (e.g. at the end)
            if len(fields) != 6:
                raise ValueError(f"{path}:{line_no}: {len(fields)} fields, expected 6")
            try:
                face, corner = int(fields[0]), int(fields[1])
                t = (float(fields[2]), float(fields[3]), float(fields[4]))
                sign = float(fields[5])
            except ValueError:
                raise ValueError(f"{path}:{line_no}: not a number in {line.strip()!r}") from None
            if not all(math.isfinite(x) for x in t) or sign not in (1.0, -1.0):
                raise ValueError(f"{path}:{line_no}: non-finite tangent or sign not +-1: "
                                 f"{line.strip()!r}")
            rows.append((face, corner, t, sign))
    return rows
