#!/usr/bin/env python3
"""The BlenderSubdivisionOracle test: sgbake's --subdivide against Blender's Subdivision Surface.

    python3 tests/blender/subdivision_oracle.py --cli build/src/sgbake
        [--blender blender] [--keep DIR]

1. Runs make_subdivision_cases.py inside Blender (headless, factory settings, once for all
   cases): it writes nine coarse meshes (cube; Suzanne, triangles and quads; a 7-sided cylinder
   with n-gon caps; a wavy open grid; creased copies of the cube, Suzanne and the cylinder,
   with Edge and Vertex Creases; the cube and Suzanne with some faces flat-shaded, marked with
   `s 0` / `s 1`) as OBJ, with their creases in cases.json, and, for each case
   (mesh, level, UV Smooth, Boundary Smooth, Use Creases, Quality, Use Limit Surface, type
   Catmull-Clark or Simple, the mesh's Auto Smooth), the mesh Blender's modifier makes with its MikkTSpace tangents (`Mesh.calc_tangents()`)
   as NPZ.
2. For each case runs
     sgbake tangents MESH.obj --subdivide L --uv-smooth U --boundary-smooth B
                    [--edge-crease A,B,C ... --vertex-crease V,C ... (the mesh's creases)]
                    [--no-creases (Use Creases off)] [--subdivision-quality Q]
                    [--no-limit-surface (Use Limit Surface off)] [--subdivision-type simple]
                    [--auto-smooth DEG (the mesh's Auto Smooth)] [--sharp-edge A,B ...]
                    --mesh-out TAG.sgbake.obj -o TAG.sgbake.csv
   and compares sgbake's subdivided mesh and tangents with Blender's (numpy, no Blender; when
   the python3 running this has no numpy, e.g. a pyenv one under CTest, it hands the comparison
   to Blender's own Python interpreter, which has numpy, as `--compare-only DIR`):
     counts     the same numbers of vertices and faces;
     vertices   each sgbake vertex's nearest Blender vertex is a different one (bijective;
                vertices at exactly the same place on both sides are paired in index order);
     positions  every vertex is Blender's float32, bit for bit (sgbake evaluates Blender's
                way: Far patches refined to Quality 3, Osd's CPU evaluator in float, the
                same Ptex face and (u, v) for every point; see docs/subdivision.md);
     faces      every Blender face is an sgbake face with the same vertex cycle, its first
                corner the same or the opposite one (the same diagonal: Blender splits a quad
                0-1-2 / 0-2-3), and no face is left over;
     order      sgbake's face f is Blender's face f, from the same first corner (so row k of
                `tangents` is Blender's loop k);
     normals    per matched corner, the angle between sgbake's `vn` and Blender's split normal
                <= 0.05 deg (0.0017 deg measured; flat-shaded faces included);
     uvs        per matched corner, max |du|, |dv| <= 2.5e-7, and the corners whose UV is not
                Blender's float are counted (0 but on the grid, there up to ~28 a run): Blender
                gives a face-varying value shared by corners with nearly equal UVs the UV of
                whichever corner its threads write last, which changes from run to run (the
                grid: 28 of 192 corners); sgbake takes the one written last in order;
     tangents   max angle <= 0.05 deg and identical bitangent signs, every case (measured
                <= 0.002 deg: MikkTSpace's float rounding), except at the corners of a vertex
                of the faces around a vertex where this Blender run gave a corner a UV an ulp
                off (see uvs): MikkTSpace welds that vertex differently, which joins its faces
                differently (up to 0.52 deg seen on the grid); the t columns show every corner.
3. Negative controls, which must FAIL, or the checks could not tell right from wrong:
     boundary   sgbake --boundary-smooth keep-corners against Blender's grid made with ALL
                (level 1): the position check must fail;
     level      sgbake --subdivide 1 against Blender's level-2 grid: the count check must fail;
     creases    sgbake --no-creases against Blender's creased cube (level 2) and creased Suzanne
                (level 1): the position check must fail (0.37 and 0.026 off);
     flat faces sgbake on the flat-shaded Suzanne's OBJ without its `s` lines (level 1): the
                normal check must fail (62 deg off);
     sharpness 10c  sgbake given sqrt(c) for every crease c, i.e. sharpness 10 c instead of
                Blender's 10 c^2, against the creased cube (level 1): the position check must
                fail (0.20 off);
     quality    sgbake at the default Quality 3 against Blender's creased cube at Quality 5
                (level 2): the position check must fail;
     limit surface  sgbake on the limit surface against Blender's Suzanne with Use Limit
                Surface off (level 2): the position check must fail;
     simple     sgbake's Catmull-Clark against Blender's Simple creased cylinder (level 2): the
                position check must fail;
     auto smooth  sgbake without --auto-smooth against Blender's creased cube with Auto Smooth
                30 deg, and at 40 deg against Blender's flat-faced Suzanne at 20 deg: the normal
                check must fail;
     sharp edges  sgbake without the --sharp-edge marks against Blender's Suzanne with every
                5th edge marked sharp (Auto Smooth 180 deg): the normal check must fail;
     level 0    the same two at level 0 (the mesh as it is, with its own split normals):
                sgbake without --auto-smooth (the OBJ's normals) against Blender's flat-faced
                Suzanne at 20 deg, and without the marks against Suzanne's every 5th edge.

Prints one line of figures per case (D, the largest position error and the vertices that
differ, unmatched faces and diagonal mismatches, UV max and the corners that differ, tangent
median / p99 / max in degrees and sign mismatches). --keep DIR writes every file
there and keeps it.

Exit status: 0 pass, 1 fail (or a tool failed), 2 usage error, 77 Blender is not installed
(CTest: SKIP_RETURN_CODE 77). Takes ~4 s: Blender starts once for all cases.
"""

import argparse
import importlib.util
import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, HERE)
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

BLENDER_TIMEOUT = 240
SGBAKE_TIMEOUT = 120

# Positions must be Blender's floats exactly. UVs may differ by an ulp or two (up to 2: 2.4e-7
# at most): where corners of a vertex share a face-varying value but not quite the same UV,
# Blender's value is whichever corner's UV its evaluator was given last, and that changes from
# run to run (measured: 28 of 192 corners of the grid between two runs); sgbake takes the
# corner Blender takes when it runs in order. Tangents: MikkTSpace's float rounding only.
UV_MAX = 2.5e-7
TANGENT_MAX_DEG = 0.05
NORMAL_MAX_DEG = 0.05

# Blender's enum names -> sgbake's option values: the add-on's own table (plugin/, no bpy in
# that module), so that these cases check it too.
_ADDON_SCENE = importlib.util.spec_from_file_location(
    "sgbake_addon_scene", os.path.join(os.path.dirname(os.path.dirname(HERE)), "plugin",
                                       "sgbake_blender", "scene.py"))
_addon_scene = importlib.util.module_from_spec(_ADDON_SCENE)
_ADDON_SCENE.loader.exec_module(_addon_scene)
UV_SMOOTH = _addon_scene.UV_SMOOTHS
BOUNDARY_SMOOTH = _addon_scene.BOUNDARY_SMOOTHS

# Negative controls: (name, Blender's case, sgbake option overrides, the check that must fail).
# An override of None drops the option; "--no-creases": "" adds the flag.
CONTROLS = [
    ("boundary", "grid_L1_PRESERVE_BOUNDARIES_ALL", {"--boundary-smooth": "keep-corners"},
     "positions"),
    ("level", "grid_L2_PRESERVE_BOUNDARIES_ALL", {"--subdivide": "1"}, "counts"),
    ("creases", "cube_creased_L2_PRESERVE_BOUNDARIES_ALL", {"--no-creases": ""}, "positions"),
    ("suzanne creases", "suzanne_creased_L1_PRESERVE_BOUNDARIES_ALL", {"--no-creases": ""},
     "positions"),
    ("sharpness 10c", "cube_creased_L1_PRESERVE_BOUNDARIES_ALL", {"sharpness": "10c"},
     "positions"),
    ("flat faces", "suzanne_flat_L1_PRESERVE_BOUNDARIES_ALL", {"smoothing": "strip"},
     "normals"),
    ("quality", "cube_creased_L2_PRESERVE_BOUNDARIES_ALL_Q5", {"--subdivision-quality": None},
     "positions"),
    ("limit surface", "suzanne_L2_PRESERVE_BOUNDARIES_ALL_nolimit", {"--no-limit-surface": None},
     "positions"),
    ("simple", "cylinder_creased_L2_SMOOTH_ALL_ALL_simple", {"--subdivision-type": None},
     "positions"),
    ("auto smooth", "cube_creased_L2_PRESERVE_BOUNDARIES_ALL_autosmooth30",
     {"--auto-smooth": None}, "normals"),
    ("auto smooth angle", "suzanne_flat_L1_PRESERVE_BOUNDARIES_ALL_autosmooth20",
     {"--auto-smooth": "40"}, "normals"),
    ("sharp edges", "suzanne_L1_PRESERVE_BOUNDARIES_ALL_autosmooth180_sharp5",
     {"no sharp edges": True}, "normals"),
    ("auto smooth level 0", "suzanne_flat_L0_PRESERVE_BOUNDARIES_ALL_autosmooth20",
     {"--auto-smooth": None}, "normals"),
    ("sharp edges level 0", "suzanne_L0_PRESERVE_BOUNDARIES_ALL_autosmooth180_sharp5",
     {"no sharp edges": True}, "normals"),
]


# ---------------------------------------------------------------------------------------------
# Running Blender and sgbake


def make_cases(blender, out_dir):
    """Runs the case generator in Blender; returns True on success (prints Blender's output
    on failure)."""
    try:
        proc = objio.run_blender(blender, os.path.join(HERE, "make_subdivision_cases.py"),
                                 [out_dir], capture_output=True, text=True,
                                 timeout=BLENDER_TIMEOUT)
    except subprocess.TimeoutExpired:
        print(f"error: Blender did not finish make_subdivision_cases.py in {BLENDER_TIMEOUT} s")
        return False
    if proc.returncode != 0:
        print(f"error: `{' '.join(proc.args)}` exited with {proc.returncode}\n"
              f"{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}")
        return False
    return True


def crease_options(mesh, sharpness="10c^2"):
    """sgbake's --edge-crease / --vertex-crease options for the creases Blender's mesh has
    (make_subdivision_cases.py lists them). sharpness "10c" passes sqrt(c) instead of c, so
    that sgbake's 10 c^2 becomes 10 c: the mapping a negative control must tell apart."""
    import math
    value = (lambda c: c) if sharpness == "10c^2" else math.sqrt
    cmd = []
    for v0, v1, crease in mesh.get("edge_creases", []):
        cmd += ["--edge-crease", f"{v0},{v1},{value(crease)!r}"]
    for v, crease in mesh.get("vertex_creases", []):
        cmd += ["--vertex-crease", f"{v},{value(crease)!r}"]
    return cmd


def run_sgbake(cli, work, case, mesh, overrides, out_name):
    """Runs `sgbake tangents` on the case's coarse mesh with the case's settings and the
    mesh's creases (and the overrides); returns (OBJ path, CSV path) or an error message."""
    overrides = dict(overrides)
    sharpness = overrides.pop("sharpness", "10c^2")
    sharp_edges = [] if overrides.pop("no sharp edges", False) else case.get("sharp_edges", [])
    mesh_obj = os.path.join(work, case["mesh"] + ".obj")
    if overrides.pop("smoothing", None) == "strip":  # the OBJ without its `s` lines
        with open(mesh_obj, encoding="ascii") as f:
            lines = [line for line in f if not line.startswith("s ")]
        mesh_obj = os.path.join(work, out_name + ".stripped.obj")
        with open(mesh_obj, "w", encoding="ascii") as f:
            f.writelines(lines)
    options = {
        "--subdivide": str(case["level"]),
        "--uv-smooth": UV_SMOOTH[case["uv_smooth"]],
        "--boundary-smooth": BOUNDARY_SMOOTH[case["boundary_smooth"]],
    }
    if not case.get("use_creases", True):
        options["--no-creases"] = ""
    if case.get("quality", 3) != 3:
        options["--subdivision-quality"] = str(case["quality"])
    if not case.get("use_limit_surface", True):
        options["--no-limit-surface"] = ""
    if case.get("subdivision_type", "CATMULL_CLARK") == "SIMPLE":
        options["--subdivision-type"] = "simple"
    if case.get("auto_smooth") is not None:
        options["--auto-smooth"] = repr(case["auto_smooth"])
    options.update(overrides)
    obj = os.path.join(work, out_name + ".sgbake.obj")
    csv = os.path.join(work, out_name + ".sgbake.csv")
    cmd = [cli, "tangents", mesh_obj]
    cmd += crease_options(mesh, sharpness)
    for v0, v1 in sharp_edges:
        cmd += ["--sharp-edge", f"{v0},{v1}"]
    for key, value in options.items():
        if value is not None:
            cmd += [key, value] if value != "" else [key]
    cmd += ["--mesh-out", obj, "-o", csv]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=SGBAKE_TIMEOUT,
                              check=False)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return f"`{' '.join(cmd)}`: {exc}"
    if proc.returncode != 0:
        return (f"`{' '.join(cmd)}` exited with {proc.returncode}: "
                f"{proc.stderr.strip()[-2000:]}")
    return obj, csv


# ---------------------------------------------------------------------------------------------
# Reading sgbake's output


def read_obj(path):
    """Reads the OBJ sgbake's --mesh-out writes (v; vt per corner; vn per corner; f v/vt/vn).

    Returns (positions (V, 3) float64, uvs (T, 2) float64, face_size (F,) int64,
    corner_vertex (C,) int64, corner_uv (C,) int64, corner normals (C, 3) float64), indices
    0-based."""
    import numpy as np
    positions, uvs, normals, face_size, corner_vertex, corner_uv, corner_normal = (
        [], [], [], [], [], [], [])
    with open(path, "r", encoding="ascii", errors="replace") as f:
        for line_no, line in enumerate(f, start=1):
            words = line.split()
            if not words or words[0].startswith("#"):
                continue
            try:
                if words[0] == "v":
                    positions.append([float(x) for x in words[1:4]])
                elif words[0] == "vt":
                    uvs.append([float(x) for x in words[1:3]])
                elif words[0] == "vn":
                    normals.append([float(x) for x in words[1:4]])
                elif words[0] == "f":
                    face_size.append(len(words) - 1)
                    for token in words[1:]:
                        fields = token.split("/")
                        corner_vertex.append(int(fields[0]) - 1)
                        corner_uv.append(int(fields[1]) - 1)
                        corner_normal.append(int(fields[2]) - 1)
            except (ValueError, IndexError):
                raise ValueError(f"{path}:{line_no}: cannot parse {line.strip()!r}") from None
    positions = np.array(positions, dtype=np.float64).reshape(-1, 3)
    uvs = np.array(uvs, dtype=np.float64).reshape(-1, 2)
    corner_vertex = np.array(corner_vertex, dtype=np.int64)
    corner_uv = np.array(corner_uv, dtype=np.int64)
    if (corner_vertex.size and (corner_vertex.min() < 0 or corner_vertex.max() >= len(positions)
                                or corner_uv.min() < 0 or corner_uv.max() >= len(uvs))):
        raise ValueError(f"{path}: a face refers to a missing v or vt")
    normals = np.array(normals, dtype=np.float64).reshape(-1, 3)
    corner_normal = np.array(corner_normal, dtype=np.int64)
    if corner_normal.size and (corner_normal.min() < 0 or corner_normal.max() >= len(normals)):
        raise ValueError(f"{path}: a face refers to a missing vn")
    return (positions, uvs, np.array(face_size, dtype=np.int64), corner_vertex, corner_uv,
            normals[corner_normal])


def read_tangents(path, face_size):
    """Reads sgbake's tangent CSV; returns (tangents (C, 3) float64, signs (C,) float64) after
    checking that its rows are the corners of the faces in order."""
    import numpy as np
    rows = objio.read_tangent_csv(path)
    face, corner = objio.corner_ids(face_size)
    if len(rows) != len(face):
        raise ValueError(f"{path}: {len(rows)} rows for {len(face)} corners")
    ids = np.array([(r[0], r[1]) for r in rows], dtype=np.int64).reshape(-1, 2)
    if not (np.array_equal(ids[:, 0], face) and np.array_equal(ids[:, 1], corner)):
        raise ValueError(f"{path}: rows are not the mesh's corners in face order")
    return (np.array([r[2] for r in rows], dtype=np.float64).reshape(-1, 3),
            np.array([r[3] for r in rows], dtype=np.float64))


# ---------------------------------------------------------------------------------------------
# Comparison


def nearest(points, reference):
    """Index of the nearest reference point of every point and the distance to it."""
    import numpy as np
    ref_sq = (reference * reference).sum(1)
    index = np.empty(len(points), dtype=np.int64)
    for start in range(0, len(points), 512):
        chunk = points[start:start + 512]
        # |p - r|^2 up to the constant |p|^2; the exact distance is taken below.
        d2 = ref_sq[None, :] - 2.0 * chunk @ reference.T
        index[start:start + 512] = d2.argmin(1)
    return index, np.linalg.norm(points - reference[index], axis=1)


def split_coincident(points, reference, index):
    """Where several points took the same nearest reference point and the reference has
    exactly that many points at that place (coincident vertices, e.g. Suzanne's two pairs, kept
    coincident by Simple subdivision), pairs them in index order: position cannot tell them
    apart, and both meshes number vertices in the same order."""
    import numpy as np
    index = index.copy()
    points, reference = points.astype(np.float32), reference.astype(np.float32)
    targets, counts = np.unique(index, return_counts=True)
    for target in targets[counts > 1]:
        mine = np.flatnonzero(index == target)
        theirs = np.flatnonzero((reference == reference[target]).all(1))
        if len(theirs) == len(mine) and (points[mine] == reference[target]).all():
            index[mine] = theirs
    return index


def angles_deg(a, b):
    """Angles between the rows of a and b in degrees, accurate for tiny angles (atan2)."""
    import numpy as np
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), (a * b).sum(1)))


def compare(case, ref, obj, csv):
    """Compares sgbake's subdivided mesh and tangents with Blender's. Returns (figures,
    failures), failures a list of (check, message); figures are None when the counts differ
    (nothing else can be compared)."""
    import numpy as np
    P, T, face_size, corner_vertex, corner_uv, N = read_obj(obj)
    tangents, signs = read_tangents(csv, face_size)
    BP = ref["positions"].astype(np.float64)
    b_size, b_vertex = ref["face_size"], ref["corner_vertex"]
    BU, BT, BS = (ref["uvs"].astype(np.float64), ref["tangents"].astype(np.float64),
                  ref["signs"])
    failures = []
    if len(P) != len(BP) or len(face_size) != len(b_size):
        failures.append(("counts", f"sgbake made {len(P)} vertices and {len(face_size)} faces, "
                                   f"Blender {len(BP)} and {len(b_size)}"))
        return None, failures
    fig = {"vertices": len(BP), "faces": len(b_size)}

    # Vertices: nearest Blender vertex, bijective; positions relative to the bbox diagonal.
    index, dist = nearest(P, BP)
    index = split_coincident(P, BP, index)
    dist = np.linalg.norm(P - BP[index], axis=1)
    matched = len(np.unique(index))
    if matched != len(P):
        failures.append(("vertices", f"{len(P) - matched} sgbake vertices share their nearest "
                                     "Blender vertex with another one"))
    diag = float(np.linalg.norm(BP.max(0) - BP.min(0)))
    # Bit for bit: sgbake's OBJ holds its floats exactly (9 digits), Blender's NPZ float32.
    inexact = int((P.astype(np.float32) != BP[index].astype(np.float32)).any(1).sum())
    fig.update(diag=diag, pos_max=float(dist.max()) if dist.size else 0.0, pos_inexact=inexact)
    if inexact:
        failures.append(("positions", f"{inexact} vertices are not Blender's floats (max "
                                      f"distance {dist.max():.3g}, {dist.max() / diag:.2g} x D)"))

    # Faces: same vertex cycle, first corner the same or opposite; corners paired up.
    b_start = np.concatenate(([0], np.cumsum(b_size)))
    by_vertices = {}
    for f in range(len(b_size)):
        cycle = b_vertex[b_start[f]:b_start[f + 1]]
        by_vertices.setdefault(tuple(sorted(cycle.tolist())), []).append(f)
    start = np.concatenate(([0], np.cumsum(face_size)))
    mapped = index[corner_vertex]
    used = np.zeros(len(b_size), dtype=bool)
    ours_corners, blender_corners = [], []
    unmatched = diagonal = misordered = 0
    for f in range(len(face_size)):
        n = int(face_size[f])
        cycle = mapped[start[f]:start[f + 1]].tolist()
        hit = None
        for bf in by_vertices.get(tuple(sorted(cycle)), ()):
            b_cycle = b_vertex[b_start[bf]:b_start[bf + 1]].tolist()
            if used[bf] or len(b_cycle) != n:
                continue
            for shift in range(n):  # our corner j is Blender's corner (j + shift) % n
                if all(b_cycle[(j + shift) % n] == cycle[j] for j in range(n)):
                    hit = (bf, shift)
                    break
            if hit:
                break
        if hit is None:
            unmatched += 1
            continue
        bf, shift = hit
        used[bf] = True
        if bf != f or shift != 0:  # not Blender's face f, starting at its first corner
            misordered += 1
        if n == 4 and shift % 2:
            diagonal += 1
        ours_corners += range(start[f], start[f + 1])
        blender_corners += [b_start[bf] + (j + shift) % n for j in range(n)]
    unmatched = max(unmatched, int((~used).sum()))
    fig.update(unmatched=unmatched, diagonal=diagonal, misordered=misordered)
    if misordered:
        failures.append(("order", f"{misordered} sgbake faces are not Blender's face of the same "
                                  "index, or start at another corner"))
    if unmatched:
        failures.append(("faces", f"{unmatched} Blender faces have no sgbake face with the "
                                  "same vertex cycle"))
    if diagonal:
        failures.append(("faces", f"{diagonal} quads start at a neighbouring corner of "
                                  "Blender's (the other triangulation diagonal)"))
    if not ours_corners:
        return fig, failures + [("faces", "no face matches")]

    # UVs and tangents of the matched corners.
    ours_corners = np.array(ours_corners)
    blender_corners = np.array(blender_corners)
    ours_uv = T[corner_uv[ours_corners]].astype(np.float32)
    blender_uv = BU[blender_corners].astype(np.float32)
    uv_error = np.abs(ours_uv.astype(np.float64) - blender_uv).max(1)
    normal_angle = angles_deg(N[ours_corners], ref["normals"].astype(np.float64)[blender_corners])
    fig.update(n_max=float(normal_angle.max()) if normal_angle.size else 0.0)
    if fig["n_max"] > NORMAL_MAX_DEG:
        failures.append(("normals", f"corner normals differ by up to {fig['n_max']:.4f} deg "
                                    f"(> {NORMAL_MAX_DEG} deg)"))
    angle = angles_deg(tangents[ours_corners], BT[blender_corners])
    same_sign = np.sign(signs[ours_corners]) == np.sign(BS[blender_corners])
    uv_inexact = (ours_uv != blender_uv).any(1)
    # Where this Blender run gave a corner a UV one ulp off (see UV_MAX), MikkTSpace welds that
    # vertex's corners differently, in Blender or in sgbake, and so joins the faces around it
    # differently: the tangents are asserted at every vertex but those of the faces around such
    # a vertex (at all of them when every UV is Blender's).
    inexact_vertices = np.unique(corner_vertex[ours_corners[uv_inexact]])
    face_of = np.repeat(np.arange(len(face_size)), face_size)
    near_faces = np.unique(face_of[np.isin(corner_vertex, inexact_vertices)])
    excluded = np.unique(corner_vertex[np.isin(face_of, near_faces)])
    asserted = ~np.isin(corner_vertex[ours_corners], excluded)
    sign_diff = int((~same_sign[asserted]).sum())
    fig.update(uv_max=float(uv_error.max()), uv_inexact=int(uv_inexact.sum()),
               t_median=float(np.median(angle)), t_p99=float(np.percentile(angle, 99)),
               t_max=float(angle.max()), sign_diff=sign_diff)
    t_asserted = float(angle[asserted].max()) if asserted.any() else 0.0
    if fig["uv_max"] > UV_MAX:
        failures.append(("uvs", f"UVs differ by up to {fig['uv_max']:.3g} (> {UV_MAX:g})"))
    if t_asserted > TANGENT_MAX_DEG:
        failures.append(("tangents", f"tangents differ by up to {t_asserted:.4f} deg "
                                     f"(> {TANGENT_MAX_DEG} deg)"))
    if sign_diff:
        failures.append(("tangents", f"{sign_diff} bitangent signs differ"))
    return fig, failures


HEADER = ("%-45s %6s %6s %6s %9s %6s %7s %9s %6s %7s %7s %7s %4s %7s  %s"
          % ("case (Blender enums)", "verts", "faces", "D", "pos max", "pos!=", "unm/dg",
             "uv max", "uv!=", "t med", "t p99", "t max", "sgn", "n max", "result"))


def table_row(label, fig, failures):
    if fig is None:
        return "%-45s %s  FAIL (%s)" % (label, "counts differ", "; ".join(m for _, m in failures))
    tangent = ("%7.4f %7.4f %7.4f %4d" % (fig["t_median"], fig["t_p99"], fig["t_max"],
                                          fig["sign_diff"]) if "t_max" in fig else "-")
    return ("%-45s %6d %6d %6.3f %9.2e %6d %3d/%-3d %9.2e %6s %s %7.4f %s"
            % (label, fig["vertices"], fig["faces"], fig["diag"], fig["pos_max"],
               fig["pos_inexact"], fig["unmatched"], fig["diagonal"],
               fig.get("uv_max", float("nan")), fig.get("uv_inexact", "-"), tangent,
               fig.get("n_max", float("nan")), "ok" if not failures else "FAIL"))


def compare_all(cli, work):
    """Runs sgbake on every case in WORK (made by make_subdivision_cases.py) and on the negative
    controls, prints the figures and the verdict; returns the exit status (0 or 1)."""
    import numpy as np
    with open(os.path.join(work, "cases.json"), encoding="ascii") as f:
        manifest = json.load(f)
    cases = {c["tag"]: c for c in manifest["cases"]}
    print(f"Blender {manifest['blender']}, {len(cases)} cases; coarse meshes: "
          + ", ".join(f"{name} {m['vertices']} v / {m['faces']} f / {m['valence2']} corners"
                      for name, m in manifest["meshes"].items()))
    print("D = bounding-box diagonal; pos max = largest |sgbake - Blender| (as parsed from the "
          "files), pos!= = vertices\nwhose float32 differs; unm/dg = unmatched faces / diagonal "
          "mismatches; uv max = max |du|, |dv| per\ncorner, uv!= = corners whose float32 UV "
          "differs; t = tangent angle in degrees; sgn = sign mismatches")
    print(HEADER)
    failures = []
    def run_and_compare(tag, overrides, out_tag):
        """sgbake on Blender's case `tag` with `overrides`; (figures, failed checks), or the
        reason it could not be compared as a string."""
        case = cases[tag]
        mesh = manifest["meshes"][case["mesh"]]
        result = run_sgbake(cli, work, case, mesh, overrides, out_tag)
        if isinstance(result, str):
            return f"sgbake failed: {result}"
        try:
            return compare(case, np.load(os.path.join(work, tag + ".npz")), *result)
        except (OSError, ValueError) as exc:
            return f"cannot compare: {exc}"

    for tag in cases:
        outcome = run_and_compare(tag, {}, tag)
        if isinstance(outcome, str):
            failures.append(f"{tag}: {outcome}")
            print("%-45s %s" % (tag, outcome))
            continue
        fig, fails = outcome
        print(table_row(tag, fig, fails))
        failures += [f"{tag}: {check}: {message}" for check, message in fails]

    for name, tag, overrides, must_fail in CONTROLS:
        options = " ".join(f"{k} {v}" for k, v in overrides.items())
        outcome = run_and_compare(tag, overrides, "control_" + name.replace(" ", "_"))
        if isinstance(outcome, str):
            failures.append(f"control {name}: {outcome}")
            continue
        _, fails = outcome
        failed = [message for check, message in fails if check == must_fail]
        if failed:
            print(f"control {name} (sgbake {options} vs Blender's {tag}): control failed as "
                  f"expected: {must_fail}: {failed[0]}")
        else:
            print(f"control {name} (sgbake {options} vs Blender's {tag}): PASSED the "
                  f"{must_fail} check")
            failures.append(f"negative control {name}: sgbake with {options} passes the "
                            f"{must_fail} check against {tag}, so the check cannot tell right "
                            "from wrong")

    return bc.report(failures, f"PASS: {len(cases)} cases agree with Blender, {len(CONTROLS)} "
                               "negative controls fail")


def has_numpy():
    try:
        import numpy  # noqa: F401
    except ImportError:
        return False
    return True


def main():
    parser = bc.oracle_parser(
        __doc__, blender_help="Blender executable (default: `blender` on PATH)")
    # Internal: compare the cases already in DIR (how the driver hands the comparison to
    # Blender's Python when its own has no numpy).
    parser.add_argument("--compare-only", metavar="DIR", help=argparse.SUPPRESS)
    args = parser.parse_args()

    if args.compare_only:
        if not has_numpy():
            print(f"error: {sys.executable} has no numpy")
            return 2
        return compare_all(args.cli, args.compare_only)

    blender = bc.blender_or_skip(args.blender)
    bc.require_executable(args.cli)
    cli = os.path.abspath(args.cli)

    started = time.perf_counter()
    with bc.work_dir(args.keep, "sgbake-subdiv-oracle-") as work:
        if not make_cases(blender, work):
            return 1
        blender_s = time.perf_counter() - started
        if has_numpy():
            status = compare_all(cli, work)
        else:
            with open(os.path.join(work, "cases.json"), encoding="ascii") as f:
                python = json.load(f)["python"]
            print(f"note: {sys.executable} has no numpy; comparing with Blender's Python "
                  f"{python}")
            sys.stdout.flush()
            try:
                status = subprocess.run([python, os.path.abspath(__file__), "--cli", cli,
                                         "--compare-only", work], check=False).returncode
            except OSError as exc:
                print(f"error: cannot run {python}: {exc}")
                status = 1
        if args.keep:
            print(f"files kept in {work}")
    print(f"time: {time.perf_counter() - started:.1f} s (Blender {blender_s:.1f} s)")
    return status


if __name__ == "__main__":
    sys.exit(main())
