#!/usr/bin/env python3
"""sgbake's loop triangles (`sgbake_loop_triangles`, the C ABI) against Blender's
(`Mesh.loop_triangles`).

Blender builds one mesh of random polygons of 5 to 545 corners (seeded): concave stars, random
self-intersecting ones (planar and not), polygons on a coarse grid (collinear and coincident
corners), tilted stars and combs (near-ties after projection), wavy rings of many corners. It
writes the float positions it stored and its loop triangles. libsgbake, loaded with ctypes,
must give every polygon the same triangles in the same order with the same corner order.
--sabotage reverses the corner order of one of sgbake's triangles: the test must then fail.

  python3 tests/blender/triangulation_oracle.py --lib build/src/libsgbake.so [--keep DIR]
Exit 0 pass, 1 fail, 77 skip (no Blender).
"""

import argparse
import ctypes
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

BLENDER_SCRIPT = r"""
import bpy, json, math, random, sys
args = sys.argv[sys.argv.index("--") + 1:]
rng = random.Random(int(args[1]))
polygons = []  # (kind, corner positions)
for n in range(300):  # star-shaped, often very concave
    k = 5 + n % 30
    angles = sorted(rng.uniform(0, 2 * math.pi) for _ in range(k))
    radii = [rng.uniform(0.05, 1) for _ in angles]
    polygons.append(("star", [(r * math.cos(a), r * math.sin(a), 0.0)
                              for a, r in zip(angles, radii)]))
for n in range(200):  # random corners: self-intersecting, planar or not
    k = 5 + n % 20
    polygons.append(("random", [(rng.uniform(-1, 1), rng.uniform(-1, 1),
                                 rng.uniform(-1, 1) if n % 2 else 0.0) for _ in range(k)]))
for n in range(300):  # on a 5 x 5 grid: collinear and coincident corners
    k = 5 + n % 15
    polygons.append(("grid", [(rng.randint(0, 4) * 0.25, rng.randint(0, 4) * 0.25, 0.0)
                              for _ in range(k)]))
for n in range(200):  # stars turned out of the xy plane
    k = 6 + n % 20
    ax, ay = rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5)
    corners = []
    for i in range(k):
        a = 2 * math.pi * i / k
        r = 1.0 if i % 2 == 0 else rng.choice([0.3, 0.5, 0.7])
        x, y = r * math.cos(a), r * math.sin(a)
        y, z = y * math.cos(ax), y * math.sin(ax)
        x, z = x * math.cos(ay) + z * math.sin(ay), -x * math.sin(ay) + z * math.cos(ay)
        corners.append((x, y, z))
    polygons.append(("tilted star", corners))
for n in range(150):  # combs on integer coordinates, tilted about x
    teeth = 2 + n % 5
    corners = [(0, 0, 0), (2 * teeth, 0, 0)]
    for t in range(teeth, 0, -1):
        corners += [(2 * t, 3, 0), (2 * t - 1, 3, 0), (2 * t - 1, 1, 0)]
    if n % 3:
        corners = corners[:-1] + [(0, 3, 0)]
    a = rng.uniform(-1, 1)
    polygons.append(("tilted comb", [(x, y * math.cos(a), y * math.sin(a))
                                     for x, y, _ in corners]))
for n in range(50):  # wavy rings of many corners
    k = 50 + 10 * n
    corners = []
    for i in range(k):
        a = 2 * math.pi * i / k
        r = 1 + 0.3 * math.sin(7 * a)
        corners.append((r * math.cos(a), r * math.sin(a), 0.05 * math.sin(3 * a)))
    polygons.append(("wavy ring", corners))

vertices, faces = [], []
for _, corners in polygons:
    faces.append(list(range(len(vertices), len(vertices) + len(corners))))
    vertices += corners
me = bpy.data.meshes.new("polygons")
me.from_pydata(vertices, [], faces)
me.calc_loop_triangles()
face_start = [p.loop_start for p in me.polygons] + [len(me.loops)]
with open(args[0], "w") as f:
    json.dump({"kinds": [kind for kind, _ in polygons],
               "positions": [list(v.co) for v in me.vertices],
               "face_start": face_start,
               "corner_vertex": [l.vertex_index for l in me.loops],
               "triangles": [list(t.loops) for t in me.loop_triangles],
               "triangle_face": [t.polygon_index for t in me.loop_triangles]}, f)
"""


def sgbake_triangles(lib_path, mesh):
    """libsgbake's loop triangles of `mesh` (the JSON Blender wrote), 3 corner indices each."""
    lib = ctypes.CDLL(lib_path)
    f = lib.sgbake_loop_triangles
    size_t, u32p = ctypes.c_size_t, ctypes.POINTER(ctypes.c_uint32)
    f.argtypes = [ctypes.POINTER(ctypes.c_float), size_t, u32p, size_t, u32p, size_t, u32p,
                  ctypes.c_char_p, size_t]
    f.restype = ctypes.c_int
    positions = [x for p in mesh["positions"] for x in p]
    face_start, corners = mesh["face_start"], mesh["corner_vertex"]
    faces = len(face_start) - 1
    count = len(corners) - 2 * faces
    out = (ctypes.c_uint32 * (3 * count))()
    error = ctypes.create_string_buffer(512)
    status = f((ctypes.c_float * len(positions))(*positions), len(mesh["positions"]),
               (ctypes.c_uint32 * len(face_start))(*face_start), faces,
               (ctypes.c_uint32 * len(corners))(*corners), len(corners), out, error,
               len(error))
    if status != 0:
        raise SystemExit(f"sgbake_loop_triangles failed ({status}): {error.value.decode()}")
    return [list(out[3 * t:3 * t + 3]) for t in range(count)]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--lib", required=True, help="libsgbake shared library")
    parser.add_argument("--blender", default=os.environ.get("SGBAKE_BLENDER", "blender"))
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--keep", help="keep the files in this directory")
    parser.add_argument("--sabotage", action="store_true",
                        help="reverse one of sgbake's triangles (the test must fail)")
    args = parser.parse_args()
    blender = bc.blender_or_skip(args.blender, test="triangulation")
    if bc.needs_asan_runtime(args.lib):
        print(f"SKIP: {args.lib} is built with AddressSanitizer; its runtime must be the first "
              "library of the process, so Python cannot load it")
        return bc.SKIP
    with bc.work_dir(args.keep, "sgbake_triangulation_") as work:
        script = os.path.join(work, "loop_triangles.py")
        with open(script, "w", encoding="ascii") as f:
            f.write(BLENDER_SCRIPT)
        out = os.path.join(work, "polygons.json")
        run = objio.run_blender(blender, script, [out, str(args.seed)],
                                    capture_output=True, text=True)
        if run.returncode != 0:
            print(f"Blender failed ({run.returncode}):\n{run.stderr[-2000:]}")
            return 1
        with open(out, encoding="ascii") as f:
            mesh = json.load(f)
    ours = sgbake_triangles(os.path.abspath(args.lib), mesh)
    if args.sabotage:
        ours[len(ours) // 2].reverse()
    theirs = mesh["triangles"]
    kinds = mesh["kinds"]
    failures = []
    if len(ours) != len(theirs):
        failures.append(f"{len(ours)} triangles, Blender {len(theirs)}")
    else:
        differing = sorted({face for face, a, b in zip(mesh["triangle_face"], ours, theirs)
                            if a != b})
        per_kind = {}
        for kind in kinds:
            per_kind.setdefault(kind, [0, 0])[1] += 1
        for face in differing:
            per_kind[kinds[face]][0] += 1
        corners = [b - a for a, b in zip(mesh["face_start"], mesh["face_start"][1:])]
        print(f"{len(kinds)} polygons of {min(corners)} to {max(corners)} corners, "
              f"{len(theirs)} triangles")
        for kind, (bad, total) in per_kind.items():
            print(f"  {kind:12s} {total - bad:4d} of {total:4d} as Blender cuts them")
        for face in differing[:5]:
            start, end = mesh["face_start"][face], mesh["face_start"][face + 1]
            mine = [t for f_, t in zip(mesh["triangle_face"], ours) if f_ == face]
            blender_tris = [t for f_, t in zip(mesh["triangle_face"], theirs) if f_ == face]
            failures.append(f"polygon {face} ({kinds[face]}, {end - start} corners): sgbake "
                            f"{mine}, Blender {blender_tris}")
        if len(differing) > 5:
            failures.append(f"... {len(differing)} polygons in all")
    return bc.report(failures)


if __name__ == "__main__":
    sys.exit(main())
