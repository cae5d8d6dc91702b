#!/usr/bin/env python3
"""Times MikkTSpace tangents: Blender's Mesh.calc_tangents() against `sgbake tangents`.

    python3 bench/tangents_vs_blender.py --cli build/src/sgbake [--check]
        [--runs 5] [--threads N] [--blender blender] [--blender-threads N]
        [--subdivisions 4] [--work-dir DIR]
    ninja -C build bench_tangents_vs_blender        # the same with --check

1. Blender half (this same file, run inside Blender): builds Suzanne, smooth, with a
   Subdivision Surface modifier of level --subdivisions applied (level 4: 125,952 quads,
   503,808 corners), computes split normals, then times calc_normals_split() and
   calc_tangents() separately: one warm-up, then the best of --runs (time.perf_counter).
   It also records process CPU time over wall time during calc_tangents, i.e. how many cores
   Blender kept busy. Before that it writes the coarse Suzanne (SUZANNE_coarse.obj) and times
   the modifier itself, best of --runs: the object's data tagged, the depsgraph re-evaluated
   and the result copied out with to_mesh(). It writes the mesh as OBJ with tests/blender/objio.py (the same writer as
   the oracle test) and prints its results as a JSON line tagged BLENDER_RESULT.
2. Driver half (plain python3): runs `sgbake tangents MESH.obj -o OUT.csv --stats` --runs
   times and takes the best `tangents_s` from the JSON line on stderr; then `sgbake tangents
   SUZANNE_coarse.obj --subdivide LEVEL --stats` and takes the best `subdivide_s`.

Prints one JSON line: blender_calc_tangents_s, blender_calc_normals_split_s,
blender_cpu_over_wall, blender_threads, sgbake_tangents_s, sgbake_load_s, ratio (sgbake /
Blender), corners, faces, threads (sgbake's), blender_subdivide_s, sgbake_subdivide_s and
subdivide_ratio (sgbake / Blender; reported, not checked). With --check the exit status is 1 when ratio > 0.5.
Exit 2 on usage errors or a failed run, 77 when Blender is not installed.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, os.path.join(HERE, "..", "tests", "blender"))
import objio  # noqa: E402  (needs the sys.path entry above)

RESULT_TAG = "BLENDER_RESULT "
TARGET_RATIO = 0.5  # sgbake must take at most half of Blender's time


# ---------------------------------------------------------------------------------------------
# Blender half


def best_of(runs, fn):
    """Calls fn once to warm up, then `runs` times; returns (best wall s, CPU/wall of that run)."""
    fn()
    best, best_cpu = float("inf"), 0.0
    for _ in range(runs):
        cpu0, t0 = time.process_time(), time.perf_counter()
        fn()
        wall, cpu = time.perf_counter() - t0, time.process_time() - cpu0
        if wall < best:
            best, best_cpu = wall, cpu
    return best, best_cpu / best if best > 0 else 0.0


def blender_main(argv):
    """Inside Blender: argv = [OBJ_PATH, RUNS, SUBDIVISIONS]."""
    import bpy

    obj_path, runs, levels = argv[0], int(argv[1]), int(argv[2])
    bpy.ops.mesh.primitive_monkey_add(calc_uvs=True)
    ob = bpy.context.object
    me = ob.data
    me.polygons.foreach_set("use_smooth", [True] * len(me.polygons))
    me.calc_normals_split()
    objio.write_obj(coarse_path(obj_path), objio.mesh_arrays(me),
                    comment=f"Suzanne (Blender {bpy.app.version_string})")
    mod = ob.modifiers.new("Subdivision", "SUBSURF")
    mod.levels = levels
    mod.render_levels = levels

    # The modifier itself: tag the mesh, re-evaluate the depsgraph, copy the result out.
    depsgraph = bpy.context.evaluated_depsgraph_get()

    def subdivide():
        ob.update_tag(refresh={"DATA"})
        depsgraph.update()
        evaluated = ob.evaluated_get(depsgraph)
        evaluated.to_mesh()
        evaluated.to_mesh_clear()

    subdivide_s, _ = best_of(runs, subdivide)
    bpy.ops.object.modifier_apply(modifier=mod.name)
    me = ob.data
    uvmap = me.uv_layers.active.name

    normals_s, _ = best_of(runs, me.calc_normals_split)
    # calc_tangents() reuses the split normals already present (it computes them only when
    # there are none), so this times MikkTSpace alone.
    tangents_s, cpu_over_wall = best_of(runs, lambda: me.calc_tangents(uvmap=uvmap))

    objio.write_obj(obj_path, objio.mesh_arrays(me),
                    comment=f"Suzanne, subdivision level {levels} (Blender "
                            f"{bpy.app.version_string})")
    result = {
        "blender_version": bpy.app.version_string,
        "faces": len(me.polygons),
        "corners": len(me.loops),
        "blender_calc_normals_split_s": normals_s,
        "blender_calc_tangents_s": tangents_s,
        "blender_subdivide_s": subdivide_s,
        "blender_cpu_over_wall": cpu_over_wall,
        # Blender's task scheduler (TBB) uses this many threads unless started with -t N;
        # scene.render.threads reports the same automatic count.
        "blender_threads": bpy.context.scene.render.threads,
    }
    print(RESULT_TAG + json.dumps(result), flush=True)


# ---------------------------------------------------------------------------------------------
# Driver half


def run_blender_half(args, obj_path):
    """Runs this file inside Blender; returns its BLENDER_RESULT dict or None on failure."""
    blender_args = [obj_path, str(args.runs), str(args.subdivisions)]
    blender_options = ["-t", str(args.blender_threads)] if args.blender_threads else []
    proc = objio.run_blender(args.blender, os.path.abspath(__file__), blender_args,
                             blender_options=blender_options, capture_output=True, text=True)
    for line in proc.stdout.splitlines():
        if line.startswith(RESULT_TAG):
            return json.loads(line[len(RESULT_TAG):])
    print(f"error: Blender failed (exit {proc.returncode}):\n{proc.stdout[-3000:]}\n"
          f"{proc.stderr[-3000:]}", file=sys.stderr)
    return None


def coarse_path(obj_path):
    """Where the Blender half writes Suzanne before subdivision."""
    return os.path.splitext(obj_path)[0] + "_coarse.obj"


def run_sgbake(args, obj_path, out_path, extra=(), key="tangents_s"):
    """Runs `sgbake tangents OBJ --stats EXTRA` --runs times; returns (best `key`, its load_s)."""
    cmd = [args.cli, "tangents", obj_path, "-o", out_path, "--stats"] + list(extra)
    if args.threads is not None:
        cmd += ["--threads", str(args.threads)]
    best = None
    for _ in range(args.runs):
        proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            print(f"error: `{' '.join(cmd)}` exited with {proc.returncode}: "
                  f"{proc.stderr.strip()[:2000]}", file=sys.stderr)
            return None
        stats = None
        for line in reversed(proc.stderr.splitlines()):
            if line.startswith("{"):
                stats = json.loads(line)
                break
        if stats is None or key not in stats:
            print(f"error: no JSON line with {key} on stderr of `{' '.join(cmd)}`:\n"
                  f"{proc.stderr[-2000:]}", file=sys.stderr)
            return None
        if best is None or stats[key] < best[0]:
            best = (stats[key], stats.get("load_s"))
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", required=True, help="path to the sgbake executable")
    parser.add_argument("--check", action="store_true",
                        help=f"exit 1 unless sgbake takes at most {TARGET_RATIO} x Blender's time")
    parser.add_argument("--runs", type=int, default=5, help="timed runs on each side (default 5)")
    parser.add_argument("--threads", type=int,
                        help="pass --threads N to sgbake (default: its own, all cores)")
    parser.add_argument("--blender", default="blender", help="Blender executable")
    parser.add_argument("--blender-threads", type=int,
                        help="start Blender with -t N (default: all cores)")
    parser.add_argument("--subdivisions", type=int, default=4,
                        help="Suzanne's subdivision level (4: ~504k corners)")
    parser.add_argument("--work-dir", help="keep the OBJ and sgbake's CSV here "
                                           "(default: a temporary directory)")
    args = parser.parse_args()
    if args.runs < 1:
        parser.error("--runs must be at least 1")

    args.blender = shutil.which(args.blender) or ""
    if not args.blender:
        print("SKIP: blender is not on PATH", file=sys.stderr)
        return 77
    if not (os.path.isfile(args.cli) and os.access(args.cli, os.X_OK)):
        print(f"error: {args.cli} is not an executable file", file=sys.stderr)
        return 2

    with tempfile.TemporaryDirectory(prefix="sgbake-bench-") as tmp:
        work = args.work_dir or tmp
        os.makedirs(work, exist_ok=True)
        obj_path = os.path.join(work, f"suzanne_subsurf{args.subdivisions}.obj")
        blender = run_blender_half(args, obj_path)
        if blender is None:
            return 2
        sgbake = run_sgbake(args, obj_path, os.path.join(work, "tangents.csv"))
        if sgbake is None:
            return 2
        subdivided = run_sgbake(args, coarse_path(obj_path), os.path.join(work, "coarse.csv"),
                                ["--subdivide", str(args.subdivisions)], key="subdivide_s")
        if subdivided is None:
            return 2

    result = dict(blender)
    result["sgbake_tangents_s"] = sgbake[0]
    result["sgbake_load_s"] = sgbake[1]
    result["threads"] = args.threads if args.threads else os.cpu_count()
    result["ratio"] = sgbake[0] / blender["blender_calc_tangents_s"]
    result["sgbake_subdivide_s"] = subdivided[0]
    result["subdivide_ratio"] = subdivided[0] / blender["blender_subdivide_s"]
    print(json.dumps(result))
    if args.check and result["ratio"] > TARGET_RATIO:
        print(f"FAIL: sgbake takes {result['ratio']:.2f} x Blender's calc_tangents time "
              f"(target <= {TARGET_RATIO})", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    objio.run_script(blender_main, main)
