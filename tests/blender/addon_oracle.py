#!/usr/bin/env python3
"""The BlenderAddonBake test: the Blender add-on (plugin/) bakes what the sgbake CLI bakes.

    python3 tests/blender/addon_oracle.py --cli build/src/sgbake --library build/src/libsgbake.so
        [--blender blender] [--keep DIR] [--sabotage]

1. Blender half `make` (this file inside Blender, factory settings): builds Suzanne subdivided
   once, smooth (bake_scene.build_suzanne), a 512^2 float height image (bake_scene.height_field)
   and bake_scene's material (Image Texture -> Bump, Distance 0.1 -> BSDF). It enables the
   add-on from the repository's plugin/ folder (addon_utils, so that its preferences exist)
   with the preferences' Library path set to --library, runs "Layers from Material" (which
   must add one height layer with that image and scale = Distance x Strength), then bakes with
   `bpy.ops.object.sgbake_bake()` at 256^2 every map in CASES, each into its image; the pixels
   the image then holds are saved as addon_CASE.npy (rows top first). One case bakes into a
   Target image that starts at 64^2 (the add-on must scale it) with margin 8, 2 x 2 samples
   and alpha from coverage. mesh.obj (objio: every float exact) and height.exr (raw float) are
   the same mesh and image for the CLI. The UI's way to bake, the bake job on a worker thread
   (as the modal operator runs it), must report a progress rising to 1, and a cancel set from
   the main thread must stop it without creating an image. It also checks that bad input
   becomes an error report,
   not a traceback: a layer without an image, an object without a UV map, no active object,
   a library path that does not exist, and a scene libsgbake refuses (a normal layer with the
   hermite filter: its message must come through).
2. For each case the CLI bakes the same map from the files:
     sgbake bake --mesh mesh.obj --height height.exr --height-scale S --filter bilinear
                 --map MAP --size 256 --margin M --samples N [--green G] [--alpha]
                 --bit-depth 32 --no-manifest -o cli_CASE.exr
   with S the layer's scale as Blender holds it (float32 0.1), so both read the same number.
3. Blender half `compare` (Blender reads the EXRs; the python3 CTest finds may lack numpy):
   every texel's RGB (RGBA with alpha) of the add-on's image must equal the CLI's file within
   1e-5, and the mask exactly. Both are libsgbake's floats and the file stores float32
   exactly, but the mesh is not quite the same twice: Blender 3.4 sums vertex normals in
   parallel, so each evaluation of the mesh (the OBJ's, then each bake's to_mesh()) may move
   some normals by one float ulp (measured: 336 of 7,872 corners between two to_mesh() calls),
   and the maps that read normals then differ by as much (~6e-8) near those corners. Heights,
   derivatives and the mask, which read no normal, come out bit-identical.

--sabotage bakes the add-on's tangent-normal cases with green DirectX: the test must FAIL.
Prints per case the largest difference, where it is, and the texels compared.

Exit status: 0 pass, 1 fail (or a tool failed), 2 usage error, 77 Blender is not installed or
the library is built with AddressSanitizer (SGBAKE_SANITIZE: ASan's runtime must come first
in a process, and Blender does not start with it; CTest: SKIP_RETURN_CODE 77).
Takes ~6 s (Blender starts twice; nine CLI bakes).
"""

import argparse
import json
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
PLUGIN_DIR = os.path.join(os.path.dirname(os.path.dirname(HERE)), "plugin")
sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, HERE)
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

SIZE = 256
TOLERANCE = 1e-5
ADDON = "sgbake_blender"

# name -> (map, margin, samples, alpha, target image's initial side or None for the default
# '<object>_<map>' image)
CASES = {
    "tangent-normal": ("tangent-normal", 0, 1, False, None),
    "object-normal": ("object-normal", 0, 1, False, None),
    "height": ("height", 0, 1, False, None),
    "derivative": ("derivative", 0, 1, False, None),
    "surface-gradient": ("surface-gradient", 0, 1, False, None),
    "tangent": ("tangent", 0, 1, False, None),
    "bitangent": ("bitangent", 0, 1, False, None),
    "mask": ("mask", 0, 1, False, None),
    "tangent-normal-padded": ("tangent-normal", 8, 2, True, 64),
}


# ---------------------------------------------------------------------------------------------
# Blender halves


def expect_error(name, substring, bake):
    """Runs bake() (a bpy.ops call) that must fail with an error report containing `substring`
    (bpy.ops turns an operator's ERROR report into RuntimeError). Returns a check record."""
    try:
        result = bake()
    except RuntimeError as exc:
        message = str(exc).strip()
        return {"name": name, "ok": substring in message, "message": message,
                "expected": substring}
    return {"name": name, "ok": False, "message": f"no error (returned {result})",
            "expected": substring}


def enable_addon(library_path):
    """Enables the add-on from plugin/ as a user would (so its preferences exist) and points
    its Library preference at `library_path`."""
    import addon_utils
    import bpy
    sys.path.insert(0, PLUGIN_DIR)

    def raise_error(exc):
        raise exc
    addon_utils.enable(ADDON, default_set=True, handle_error=raise_error)
    prefs = bpy.context.preferences.addons[ADDON].preferences
    prefs.library_path = library_path
    return prefs


def build_scene(work):
    """Suzanne with the bump material; writes mesh.obj and height.exr. Returns (object, height
    image, Bump Distance)."""
    import bake_scene
    bc.reset_scene()
    ob = bake_scene.build_suzanne()
    me = ob.data
    me.calc_normals_split()
    objio.write_obj(os.path.join(work, "mesh.obj"), objio.mesh_arrays(me),
                    comment="add-on test Suzanne (tests/blender/addon_oracle.py)")
    side = bake_scene.HEIGHT_SIZE
    height = bc.new_float_image("height", side, side, bake_scene.height_field(side))
    bc.save_exr(height, os.path.join(work, "height.exr"))
    distance = bake_scene.CASES["suzanne"][2]
    mat, _ = bake_scene.make_material(height, distance)
    me.materials.append(mat)
    return ob, height, distance


def layers_from_material(settings, distance):
    """Runs "Layers from Material"; returns its manifest entry (with "error" when the layers
    are not the one bilinear height layer of 'height' with scale Distance x Strength 1)."""
    import bpy
    result = bpy.ops.object.sgbake_layers_from_material()
    layers = [{"type": layer.type, "image": layer.image.name if layer.image else None,
               "scale": layer.scale, "filter": layer.filter} for layer in settings.layers]
    entry = {"result": sorted(result), "layers": layers}
    expected = {"type": "height", "image": "height", "filter": "bilinear"}
    if (len(layers) != 1 or any(layers[0][k] != v for k, v in expected.items())
            or abs(layers[0]["scale"] - distance) > 1e-7):  # float32 0.1 x 1
        entry["error"] = f"expected one {expected} layer with scale {distance}, got {layers}"
    return entry


def bake_cases(settings, ob, work, sabotage):
    """Bakes every case of CASES with the add-on's operator; saves the image it filled as
    addon_CASE.npy. Returns {case: manifest entry}."""
    import bpy
    import numpy as np
    cases = {}
    for case, (kind, margin, samples, alpha, target_side) in CASES.items():
        settings.map = kind
        settings.width = settings.height = SIZE
        settings.margin, settings.samples, settings.use_alpha = margin, samples, alpha
        settings.green = "directx" if sabotage else "opengl"
        settings.target_image = (bc.new_float_image(f"target_{case}", target_side, target_side)
                                 if target_side else None)
        entry = cases[case] = {"map": kind, "margin": margin, "samples": samples, "alpha": alpha}
        try:
            entry["result"] = sorted(bpy.ops.object.sgbake_bake())
        except RuntimeError as exc:  # the operator reported an error
            entry.update(result=["ERROR"], error=str(exc).strip())
            continue
        image = settings.target_image or bpy.data.images[f"{ob.name}_{kind}"]
        np.save(os.path.join(work, f"addon_{case}.npy"), bc.image_array(image))
        entry.update(image=image.name, image_size=list(image.size))
    settings.target_image = None
    return cases


def error_reports(settings, prefs, height, work, library_path):
    """Bakes that must end in an error report; returns their check records."""
    import bpy
    bake = bpy.ops.object.sgbake_bake
    checks = []
    settings.map = "tangent-normal"
    layer = settings.layers.add()
    layer.name = "empty"
    checks.append(expect_error("layer without an image", "has no image", bake))
    layer.type, layer.image, layer.filter = "normal", height, "hermite"
    checks.append(expect_error("scene refused by libsgbake", "filter 'hermite' is only", bake))
    settings.layers.remove(len(settings.layers) - 1)

    prefs.library_path = os.path.join(work, "missing", "libsgbake.so")
    checks.append(expect_error("library path that does not exist", "does not exist", bake))
    prefs.library_path = library_path

    plain = bpy.data.meshes.new("no_uv")
    plain.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [], [(0, 1, 2, 3)])
    plain_ob = bpy.data.objects.new("no_uv", plain)
    bpy.context.scene.collection.objects.link(plain_ob)
    bpy.context.view_layer.objects.active = plain_ob
    checks.append(expect_error("object without a UV map", "has no UV map", bake))
    bpy.context.view_layer.objects.active = None
    checks.append(expect_error("no active object", "must be a mesh", bake))
    return checks


def worker_thread_checks(settings, ob):
    """The UI's way to bake (operators.BakeJob.run on a worker thread, as the modal operator
    runs it): progress rises to 1, and a cancel set from this thread stops the bake without
    touching any image. Returns check records like expect_error's."""
    import threading
    import bpy
    from sgbake_blender import capi, operators
    settings.map, settings.width, settings.height = "tangent-normal", 1024, 1024
    settings.target_image = None
    checks = []

    job = operators.BakeJob(bpy.context)
    seen = []
    worker = threading.Thread(target=job.run)
    worker.start()
    while worker.is_alive():
        seen.append(job.progress.fraction)
        worker.join(0.005)
    seen.append(job.progress.fraction)
    ok = job.error is None and seen[-1] == 1.0 and seen == sorted(seen)
    checks.append({"name": "progress from a worker thread", "ok": ok,
                   "expected": "no error, fractions rising to 1",
                   "message": f"error {job.error}, {len(seen)} polls, fractions "
                              f"{sorted(set(seen))[:6]}..., last {seen[-1]}"})

    name = f"{ob.name}_tangent-normal"
    if name in bpy.data.images:
        bpy.data.images.remove(bpy.data.images[name])
    job = operators.BakeJob(bpy.context)
    job.progress.cancel = 1
    worker = threading.Thread(target=job.run)
    worker.start()
    worker.join()
    ok = isinstance(job.error, capi.SgbakeCancelled) and name not in bpy.data.images
    checks.append({"name": "cancel from another thread", "ok": ok,
                   "expected": "SgbakeCancelled and no image",
                   "message": f"{type(job.error).__name__}: {job.error}"})
    settings.width = settings.height = SIZE
    return checks


def blender_make(work, library_path, sabotage):
    """Builds the scene, runs the add-on (see the module docstring), writes manifest.json."""
    import bpy
    os.environ.pop("SGBAKE_LIBRARY", None)  # the preferences' path is the one under test
    ob, height, distance = build_scene(work)
    prefs = enable_addon(library_path)
    settings = bpy.context.scene.sgbake
    from sgbake_blender import capi, library
    manifest = {"blender": bpy.app.version_string,
                "library": capi.version(library.get(bpy.context)),
                "size": SIZE, "distance": distance,
                "layers_from_material": layers_from_material(settings, distance)}
    layers = manifest["layers_from_material"]["layers"]
    manifest["scale"] = layers[0]["scale"] if layers else distance
    manifest["cases"] = bake_cases(settings, ob, work, sabotage)
    manifest["errors"] = (worker_thread_checks(settings, ob)
                          + error_reports(settings, prefs, height, work, library_path))
    with open(os.path.join(work, "manifest.json"), "w", encoding="ascii") as f:
        json.dump(manifest, f, indent=1)


def blender_compare(work):
    """Compares each addon_CASE.npy with cli_CASE.exr; writes results.json."""
    import numpy as np
    with open(os.path.join(work, "manifest.json"), encoding="ascii") as f:
        manifest = json.load(f)
    results = {}
    for case, entry in manifest["cases"].items():
        if entry["result"] != ["FINISHED"]:
            continue
        ours = np.load(os.path.join(work, f"addon_{case}.npy"))
        cli_path = os.path.join(work, f"cli_{case}.exr")
        if not os.path.exists(cli_path):
            results[case] = {"error": "no CLI output"}
            continue
        theirs = bc.load_raw(cli_path)
        if ours.shape != theirs.shape:
            results[case] = {"error": f"shapes differ: add-on {ours.shape}, CLI {theirs.shape}"}
            continue
        channels = 4 if entry["alpha"] else 3
        diff = np.abs(ours[..., :channels].astype(np.float64) - theirs[..., :channels])
        per_texel = diff.max(axis=-1)
        worst = np.unravel_index(int(per_texel.argmax()), per_texel.shape)
        covered = int(np.count_nonzero(theirs[..., 0] > 0.5)) if entry["map"] == "mask" else None
        results[case] = {
            "channels": channels,
            "max_abs": float(per_texel.max()),
            "worst_at": [int(worst[1]), int(worst[0])],  # (x, file row)
            "worst_values": [ours[worst][:channels].tolist(), theirs[worst][:channels].tolist()],
            "differing": int(np.count_nonzero(per_texel > 0)),
            "over_tolerance": int(np.count_nonzero(per_texel > TOLERANCE)),
            "exact": bool(np.array_equal(ours[..., :channels], theirs[..., :channels])),
            "texels": int(per_texel.size),
            "covered": covered,
        }
    with open(os.path.join(work, "results.json"), "w", encoding="ascii") as f:
        json.dump(results, f, indent=1)


def blender_main(argv):
    mode, work = argv[0], argv[1]
    if mode == "make":
        blender_make(work, argv[2], argv[3] == "sabotage")
    elif mode == "compare":
        blender_compare(work)
    else:
        raise SystemExit(f"unknown mode {mode}")


# ---------------------------------------------------------------------------------------------
# Driver


def run_cli(cli, work, manifest):
    """Bakes every case with the CLI; returns the failed command lines."""
    failed = []
    for case, entry in manifest["cases"].items():
        cmd = [cli, "bake", "--mesh", os.path.join(work, "mesh.obj"),
               "--height", os.path.join(work, "height.exr"),
               "--height-scale", repr(manifest["scale"]), "--filter", "bilinear",
               "--map", entry["map"], "--size", manifest["size"], "--margin", entry["margin"],
               "--samples", entry["samples"], "--bit-depth", 32, "--no-manifest",
               "-o", os.path.join(work, f"cli_{case}.exr")]
        if entry["map"] == "tangent-normal":
            cmd += ["--green", "opengl"]
        if entry["alpha"]:
            cmd.append("--alpha")
        proc = bc.run_tool(cmd, timeout=120)
        if proc is None or proc.returncode != 0:
            failed.append(" ".join(map(str, cmd)))
    return failed


def evaluate(manifest, results):
    """Prints the figures; returns a list of failures."""
    failures = []
    lfm = manifest["layers_from_material"]
    print(f"Layers from Material: {lfm['result']}, layers {lfm['layers']}")
    if "error" in lfm:
        failures.append(f"Layers from Material: {lfm['error']}")
    for case, entry in manifest["cases"].items():
        if entry["result"] != ["FINISHED"]:
            print(f"  {case:22s} the add-on's bake failed: {entry.get('error')}")
            failures.append(f"{case}: the add-on's bake returned {entry['result']}: "
                            f"{entry.get('error')}")
            continue
        if entry["image_size"] != [manifest["size"]] * 2:
            failures.append(f"{case}: image '{entry['image']}' is {entry['image_size']}, "
                            f"expected {manifest['size']}^2")
        r = results.get(case, {"error": "not compared"})
        if "error" in r:
            print(f"  {case:22s} {r['error']}")
            failures.append(f"{case}: {r['error']}")
            continue
        exact = entry["map"] == "mask"
        ok = r["exact"] if exact else r["max_abs"] <= TOLERANCE
        covered = f", {r['covered']} covered" if r["covered"] is not None else ""
        print(f"  {case:22s} max |add-on - CLI| = {r['max_abs']:.3g} over {r['channels']} "
              f"channels of {r['texels']} texels{covered}; {r['differing']} differ, "
              f"{r['over_tolerance']} by > {TOLERANCE:g} -> {'ok' if ok else 'FAIL'}")
        if not ok:
            failures.append(f"{case}: the add-on's image differs from the CLI's: max "
                            f"{r['max_abs']:.3g} at (x, row) {r['worst_at']}, add-on / CLI "
                            f"{r['worst_values']}" + (" (must be identical)" if exact else ""))
    for check in manifest["errors"]:
        print(f"  check, {check['name']}: {check['message']!r} -> "
              f"{'ok' if check['ok'] else 'FAIL'}")
        if not check["ok"]:
            failures.append(f"{check['name']}: expected an error report containing "
                            f"{check['expected']!r}, got {check['message']!r}")
    return failures


def needs_asan_runtime(library):
    """Whether the library links libasan (a SGBAKE_SANITIZE build): its dynamic section then
    names the runtime, so the file holds the string."""
    with open(library, "rb") as f:
        return b"libasan.so" in f.read()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", required=True, help="path to the sgbake executable")
    parser.add_argument("--library", required=True, help="path to libsgbake.so")
    parser.add_argument("--blender", default="blender", help="Blender executable")
    parser.add_argument("--keep", metavar="DIR", help="write every file here and keep it")
    parser.add_argument("--sabotage", action="store_true",
                        help="bake the add-on's normal maps with green DirectX (must fail)")
    args = parser.parse_args()

    blender = bc.find_blender(args.blender)
    if blender is None:
        print(f"SKIP: {args.blender} is not on PATH; the Blender add-on test needs Blender")
        return bc.SKIP
    for path, what in ((args.cli, "sgbake_cli"), (args.library, "sgbake")):
        if not os.path.isfile(path):
            print(f"error: {path} is not a file (build {what} first)")
            return 2
    library = os.path.abspath(args.library)
    if needs_asan_runtime(library):
        print(f"SKIP: {library} is built with AddressSanitizer; its runtime must be the first "
              "library of the process, so Blender cannot load it")
        return bc.SKIP

    def run_half(*half_args):
        proc = objio.run_blender(blender, os.path.abspath(__file__), list(half_args),
                                 capture_output=True, text=True, timeout=150)
        if proc.returncode != 0:
            print(f"error: Blender ({half_args[0]}) exited with {proc.returncode}\n"
                  f"{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}")
        return proc.returncode == 0

    with tempfile.TemporaryDirectory(prefix="sgbake-addon-") as tmp:
        work = os.path.abspath(args.keep or tmp)
        os.makedirs(work, exist_ok=True)
        if not run_half("make", work, library, "sabotage" if args.sabotage else "honest"):
            return 1
        with open(os.path.join(work, "manifest.json"), encoding="ascii") as f:
            manifest = json.load(f)
        print(f"Blender {manifest['blender']}, libsgbake {manifest['library']}, Suzanne "
              f"{manifest['size']}^2, height scale {manifest['scale']!r}")
        failures = [f"command failed: {cmd}" for cmd in run_cli(args.cli, work, manifest)]
        if not run_half("compare", work):
            return 1
        with open(os.path.join(work, "results.json"), encoding="ascii") as f:
            results = json.load(f)
        failures += evaluate(manifest, results)
        if args.keep:
            print(f"files kept in {work}")
    if failures:
        print(f"FAIL: {len(failures)} problem(s):")
        for line in failures:
            print("  " + line)
        return 1
    print("PASS")
    return 0


if __name__ == "__main__":
    objio.run_script(blender_main, main)
