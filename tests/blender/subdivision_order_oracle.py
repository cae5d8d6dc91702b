#!/usr/bin/env python3
"""The subdivided mesh's element order against Blender's (`sgbake tangents --subdivide N
--mesh-out`).

Blender imports each OBJ (its OBJ importer: edges numbered as BKE_mesh_calc_edges numbers them,
which the edge points' numbering follows), applies a Catmull-Clark Subdivision Surface modifier
and writes the evaluated mesh's vertex positions and face corners. sgbake subdivides the same
OBJ. Vertex i must be Blender's vertex i (within 1e-6 of the bounding-box diagonal) and face f
must be Blender's face f with the same vertex indices from the same first corner, for:
  - a mesh of a quad, a triangle, a pentagon and a hexagon with an open boundary (levels 1-3:
    n-gon sub-faces and their inner points, edge points of boundary edges);
  - Suzanne (7,872 faces, levels 1 and 2): over 1000 faces Blender spreads the edges over one
    hash table per power of two of its threads, so this case also checks that sgbake counts the
    threads as Blender does on this machine.
--sabotage swaps two of sgbake's vertices: the test must then fail.

  python3 tests/blender/subdivision_order_oracle.py --cli build/src/sgbake [--keep DIR]
Exit 0 pass, 1 fail, 77 skip (no Blender).
"""

import argparse
import json
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SUZANNE = os.path.join(HERE, "..", "..", "meshes", "suzanne.obj")

# Quad, triangle, pentagon, hexagon; the outline is an open boundary.
MIXED_OBJ = """\
v 0 0 0
v 1 0 0
v 2 0 0.2
v 0 1 0
v 1 1 0.3
v 2 1 0
v 3 0.5 0.1
v 1.5 2 0
v 0.5 1.8 0.2
v 2.8 1.6 0
vt 0 0
vt 0.25 0
vt 0.5 0.05
vt 0 0.25
vt 0.25 0.25
vt 0.5 0.25
vt 0.75 0.125
vt 0.375 0.5
vt 0.125 0.45
vt 0.7 0.4
f 1/1 2/2 5/5 4/4
f 2/2 3/3 5/5
f 3/3 7/7 10/10 6/6 5/5
f 4/4 5/5 6/6 10/10 8/8 9/9
"""

CASES = [("mixed", 1), ("mixed", 2), ("mixed", 3), ("suzanne", 1), ("suzanne", 2)]

BLENDER_SCRIPT = """
import bpy, json, sys
args = sys.argv[sys.argv.index("--") + 1:]
cases = json.loads(args[0])
for obj_path, level, out in cases:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.obj_import(filepath=obj_path)
    ob = bpy.context.selected_objects[0]
    modifier = ob.modifiers.new("subdivision", "SUBSURF")
    modifier.levels = level
    mesh = ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    with open(out, "w") as f:
        json.dump({"v": [list(v.co) for v in mesh.vertices],
                   "f": [list(p.vertices) for p in mesh.polygons]}, f)
"""


def read_obj(path):
    vertices, faces = [], []
    with open(path, encoding="ascii") as f:
        for line in f:
            words = line.split()
            if words and words[0] == "v":
                vertices.append([float(x) for x in words[1:4]])
            elif words and words[0] == "f":
                faces.append([int(c.split("/")[0]) - 1 for c in words[1:]])
    return vertices, faces


def compare(tag, blender, ours):
    """Failures (strings) of sgbake's mesh `ours` against Blender's `blender`."""
    bv, bf = blender["v"], blender["f"]
    ov, of = ours
    if len(bv) != len(ov) or len(bf) != len(of):
        return [f"{tag}: {len(ov)} vertices and {len(of)} faces, Blender {len(bv)} and {len(bf)}"]
    lo = [min(p[k] for p in bv) for k in range(3)]
    hi = [max(p[k] for p in bv) for k in range(3)]
    tolerance = 1e-6 * sum((h - l) ** 2 for h, l in zip(hi, lo)) ** 0.5
    moved = [i for i, (a, b) in enumerate(zip(bv, ov))
             if max(abs(x - y) for x, y in zip(a, b)) > tolerance]
    reordered = [f for f, (a, b) in enumerate(zip(bf, of)) if a != b]
    failures = []
    if moved:
        failures.append(f"{tag}: {len(moved)} of {len(bv)} vertices are not Blender's vertex of "
                        f"the same index (first: {moved[0]})")
    if reordered:
        failures.append(f"{tag}: {len(reordered)} of {len(bf)} faces are not Blender's face of the "
                        f"same index (first: {reordered[0]}, {of[reordered[0]]} against "
                        f"{bf[reordered[0]]})")
    print(f"{tag}: {len(ov)} vertices, {len(of)} faces: "
          f"{'ok' if not failures else 'FAIL'}")
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--cli", required=True)
    parser.add_argument("--blender", default=os.environ.get("SGBAKE_BLENDER", "blender"))
    parser.add_argument("--keep", help="keep the files in this directory")
    parser.add_argument("--sabotage", action="store_true",
                        help="swap two of sgbake's vertices (the test must fail)")
    args = parser.parse_args()
    if shutil.which(args.blender) is None:
        print(f"skipped: no Blender ('{args.blender}')")
        return 77
    with bc.work_dir(args.keep, "sgbake_subdiv_order_") as work:
        meshes = {"mixed": os.path.join(work, "mixed.obj"), "suzanne": os.path.abspath(SUZANNE)}
        with open(meshes["mixed"], "w", encoding="ascii") as f:
            f.write(MIXED_OBJ)
        script = os.path.join(work, "dump_subdivided.py")
        with open(script, "w", encoding="ascii") as f:
            f.write(BLENDER_SCRIPT)
        jobs = [(meshes[m], level, os.path.join(work, f"{m}_L{level}.blender.json"))
                for m, level in CASES]
        blender = objio.run_blender(args.blender, script, [json.dumps(jobs)],
                                    capture_output=True, text=True)
        if blender.returncode != 0:
            print(f"Blender failed ({blender.returncode}):\n{blender.stderr[-2000:]}")
            return 1
        failures = []
        for (mesh, level, reference), (name, _) in zip(jobs, CASES):
            tag = f"{name} level {level}"
            out = os.path.join(work, f"{name}_L{level}.sgbake.obj")
            run = subprocess.run([args.cli, "tangents", mesh, "--subdivide", str(level),
                                  "--mesh-out", out, "-o", out + ".csv"],
                                 capture_output=True, text=True, check=False)
            if run.returncode != 0:
                failures.append(f"{tag}: sgbake exited {run.returncode}: {run.stderr.strip()}")
                continue
            ours = read_obj(out)
            if args.sabotage:
                ours[0][0], ours[0][-1] = ours[0][-1], ours[0][0]
            with open(reference, encoding="ascii") as f:
                failures += compare(tag, json.load(f), ours)
    for failure in failures:
        print("FAIL", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
