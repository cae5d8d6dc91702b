"""Helpers shared by sgbake's baking oracle tests and the Cycles benchmark.

Imported both by plain python3 drivers (bake_oracle.py, bake_orientation.py,
bench/bake_vs_cycles.py: the pyenv python3 first on PATH has no numpy) and by the scripts
that run inside Blender (bake_scene.py, bake_compare.py and the Blender halves of the others;
Blender's Python has numpy). Everything that needs numpy or bpy imports it inside the function,
so importing this module never does.

Plain-Python part
    find_blender, run_tool, parse_stats, cli_has_command, read_png (a small PNG decoder using
    only zlib, so that a driver can look at the bytes sgbake wrote without Blender or numpy).

Plain-Python part, the oracle drivers' common start and end (tests/blender/*_oracle.py,
bake_orientation.py)
    oracle_parser (--cli, --blender, --keep), blender_or_skip (exit 77 without Blender),
    require_executable (exit 2 when --cli is not a program), work_dir (a temporary directory,
    or --keep DIR left in place), report (the FAIL list or PASS, and the exit status).

Blender part (numpy and bpy)
    setup_cycles, reset_scene, new_float_image, image_array, save_exr, load_raw,
    emit_plane, bake_emit, largest_differences, fac_oracle_blender (the Fac oracles' plane,
    bakes and comparison; their driver fac_oracle_main),
    decode_normals, angle_deg, erode, angle_stats.

Conventions (docs: /work/shared/CONVENTIONS.md)
    Arrays are (H, W, C) float32 with rows TOP FIRST, i.e. in file order: element [r, x] is the
    texel at column x, file row r, whose centre is u = (x + 0.5) / W, v = 1 - (r + 0.5) / H.
    Blender's image.pixels is bottom row first; image_array / new_float_image flip it.
    Normal maps store n / 2 + 0.5 (R = +T, G = +B, B = +N in tangent space).
"""

import argparse
import contextlib
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

SKIP = 77  # exit status CTest treats as "skipped" (SKIP_RETURN_CODE)
NOT_EXECUTABLE = "error: {} is not an executable file (build sgbake_cli first)"


# ---------------------------------------------------------------------------------------------
# Plain Python (drivers)


def find_blender(name):
    """Absolute path of the Blender executable `name` (a path or a name on PATH), or None."""
    return shutil.which(name)


def oracle_parser(doc, blender_help="Blender executable",
                  keep_help="write every file here and keep it"):
    """The argument parser of an oracle driver, described by the first line of `doc` (the
    script's __doc__), with the options they all take: --cli (required: the sgbake
    executable), --blender (default `blender`; `blender_help` None shows no help text) and
    --keep DIR. The caller adds its own options after these."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--cli", required=True, help="path to the sgbake executable")
    parser.add_argument("--blender", default="blender", help=blender_help)
    parser.add_argument("--keep", metavar="DIR", help=keep_help)
    return parser


def blender_or_skip(name, test="oracle"):
    """The Blender executable `name` (a path or a name on PATH) stands for. Without one, prints
    "SKIP: NAME is not on PATH; the Blender TEST test needs Blender" and exits with SKIP (77),
    which CTest reports as a skipped test (SKIP_RETURN_CODE)."""
    blender = find_blender(name)
    if blender is None:
        print(f"SKIP: {name} is not on PATH; the Blender {test} test needs Blender")
        sys.exit(SKIP)
    return blender


def require_executable(path, message=NOT_EXECUTABLE):
    """When `path` is not an executable file, prints `message` with `path` in its {} and exits
    with 2 (a usage error, as argparse does)."""
    if not (os.path.isfile(path) and os.access(path, os.X_OK)):
        print(message.format(path))
        sys.exit(2)


@contextlib.contextmanager
def work_dir(keep, prefix):
    """`with work_dir(args.keep, prefix) as work:` - the absolute path of the directory a
    driver writes its files in: KEEP (made if need be), which is left in place, or else a new
    temporary directory named PREFIX..., which is removed with everything in it when the
    `with` block ends, however it ends."""
    if keep:
        path = os.path.abspath(keep)
        os.makedirs(path, exist_ok=True)
        yield path
        return
    path = tempfile.mkdtemp(prefix=prefix)
    try:
        yield path
    finally:
        shutil.rmtree(path, ignore_errors=True)


def needs_asan_runtime(library):
    """Whether the library links libasan (a SGBAKE_SANITIZE build): its dynamic section then
    names the runtime, so the file holds the string. Such a library cannot be loaded into a
    process (Blender, Python) whose first library is not that runtime."""
    with open(library, "rb") as f:
        return b"libasan.so" in f.read()


def report(failures, passed="PASS"):
    """Prints a driver's verdict and returns its exit status: with failures, "FAIL: N
    problem(s):" and each failure on an indented line, 1; without, the line `passed`, 0."""
    if failures:
        print(f"FAIL: {len(failures)} problem(s):")
        for line in failures:
            print("  " + line)
        return 1
    print(passed)
    return 0


def run_tool(cmd, timeout=600, quiet=False):
    """Runs a command, capturing its output. Returns the CompletedProcess, or None when it could
    not be started or timed out (after printing why). Prints the command's output when it
    fails, unless quiet."""
    try:
        proc = subprocess.run([str(c) for c in cmd], capture_output=True, text=True,
                              timeout=timeout, check=False)
    except (OSError, subprocess.TimeoutExpired) as exc:
        print(f"error: `{' '.join(map(str, cmd))}`: {exc}")
        return None
    if proc.returncode != 0 and not quiet:
        print(f"error: `{' '.join(map(str, cmd))}` exited with {proc.returncode}\n"
              f"{proc.stdout[-3000:]}{proc.stderr[-3000:]}")
    return proc


def parse_stats(stderr):
    """The last line of `stderr` that parses as a JSON object (sgbake --stats), or None."""
    for line in reversed(stderr.splitlines()):
        line = line.strip()
        if line.startswith("{"):
            try:
                value = json.loads(line)
            except ValueError:
                continue
            if isinstance(value, dict):
                return value
    return None


def cli_has_command(cli, command):
    """True when `cli --help` lists `command` among its subcommands."""
    proc = run_tool([cli, "--help"], timeout=30, quiet=True)
    if proc is None:
        return False
    for line in (proc.stdout + proc.stderr).splitlines():
        words = line.split()
        if words and words[0] == command:
            return True
    return False


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    return b if pb <= pc else c


def read_png(path):
    """Decodes a non-interlaced 8- or 16-bit grey/grey-alpha/RGB/RGBA PNG with zlib only.

    Returns (width, height, channels, bit_depth, rows): rows[r][x] is a tuple of `channels`
    floats in [0, 1] (value / 255 or / 65535), rows in FILE order (row 0 = top). Raises
    ValueError for anything else (palette images, interlacing, a corrupt file).
    """
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG file")
    pos, idat, header = 8, [], None
    while pos + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
    if header is None:
        raise ValueError(f"{path}: no IHDR chunk")
    width, height, depth, colour, _, _, interlace = header
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(colour)
    if channels is None or depth not in (8, 16) or interlace != 0:
        raise ValueError(f"{path}: unsupported PNG (colour type {colour}, depth {depth}, "
                         f"interlace {interlace})")
    raw = zlib.decompress(b"".join(idat))
    bpp = channels * depth // 8  # bytes per pixel
    stride = width * bpp
    prev = bytearray(stride)
    rows, off = [], 0
    scale = 255.0 if depth == 8 else 65535.0
    for _ in range(height):
        ftype = raw[off]
        line = bytearray(raw[off + 1:off + 1 + stride])
        off += 1 + stride
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if ftype == 1:
                line[i] = (line[i] + a) & 255
            elif ftype == 2:
                line[i] = (line[i] + b) & 255
            elif ftype == 3:
                line[i] = (line[i] + ((a + b) >> 1)) & 255
            elif ftype == 4:
                line[i] = (line[i] + _paeth(a, b, c)) & 255
            elif ftype != 0:
                raise ValueError(f"{path}: bad filter type {ftype}")
        prev = line
        if depth == 8:
            values = list(line)
        else:
            values = [(line[i] << 8) | line[i + 1] for i in range(0, stride, 2)]
        rows.append([tuple(v / scale for v in values[x * channels:(x + 1) * channels])
                     for x in range(width)])
    return width, height, channels, depth, rows


# ---------------------------------------------------------------------------------------------
# Inside Blender (numpy, bpy)


def setup_cycles(scene, samples=1, threads=None):
    """Cycles on the CPU, `samples` AA samples, denoising OFF (Debian's Cycles has no denoiser:
    with denoising on, bake() reports FINISHED and writes nothing), bake margin 0.
    threads=None keeps Blender's automatic thread count (all cores)."""
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.render.bake.margin = 0
    if threads:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = threads


def reset_scene():
    """Removes every object, mesh, material and image (so each case starts empty)."""
    import bpy
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.materials, bpy.data.images):
        for item in list(coll):
            coll.remove(item)


def set_smooth(ob, smooth):
    """Shades every face of the object smooth (vertex normals) or flat (face normals)."""
    ob.data.polygons.foreach_set("use_smooth", [smooth] * len(ob.data.polygons))
    ob.data.update()


def set_creases(ob, edge_creases, vertex_creases):
    """Blender's Edge Crease of the edges given by index, (edge, crease) pairs, and Vertex
    Crease of the vertices, (vertex, crease) pairs (the vertex crease layer is made with
    bmesh: Blender 3.4's Python API has no other way to add it)."""
    import bmesh
    me = ob.data
    bm = bmesh.new()
    bm.from_mesh(me)
    layer = bm.verts.layers.crease.verify()
    bm.verts.ensure_lookup_table()
    for v, crease in vertex_creases:
        bm.verts[v][layer] = crease
    bm.to_mesh(me)
    bm.free()
    for e, crease in edge_creases:
        me.edges[e].crease = crease
    me.update()


def read_creases(me):
    """The creases of mesh `me` as Blender holds them (float32), by vertex indices:
    ([[v0, v1, crease], ...] of every creased edge, [[v, crease], ...] of every creased
    vertex)."""
    edge_creases = [[int(e.vertices[0]), int(e.vertices[1]), float(e.crease)]
                    for e in me.edges if e.crease != 0.0]
    vertex_creases = ([[v, float(d.value)] for v, d in enumerate(me.vertex_creases[0].data)
                       if d.value != 0.0] if len(me.vertex_creases) else [])
    return edge_creases, vertex_creases


def new_float_image(name, width, height, array=None, colour=(0.0, 0.0, 0.0, 1.0)):
    """A 32-bit float, Non-Color (is_data) RGBA image. `array` (H, W, 1..4), rows top first,
    fills it (missing channels: RGB repeat the first, alpha 1); otherwise the flat `colour`."""
    import bpy
    import numpy as np
    img = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True, is_data=True)
    img.colorspace_settings.name = "Non-Color"
    if array is None:
        img.generated_color = colour
        return img
    array = np.asarray(array, dtype=np.float32)
    if array.ndim == 2:
        array = array[..., None]
    rgba = np.empty((height, width, 4), np.float32)
    rgba[..., 3] = 1.0
    for c in range(3):
        rgba[..., c] = array[..., min(c, array.shape[2] - 1)]
    if array.shape[2] == 4:
        rgba[..., 3] = array[..., 3]
    img.pixels.foreach_set(rgba[::-1].ravel())  # Blender stores the bottom row first
    img.update()
    return img


def load_tiled(template, tiles):
    """The tile files of `template` (<UDIM> in its name) as one tiled Non-Color image, which
    must come out with exactly the tiles `tiles`, each with pixels (RuntimeError otherwise).
    Blender finds the tiles from the first one's file name once the source is TILED."""
    import bpy
    img = bpy.data.images.load(template.replace("<UDIM>", str(min(tiles))))
    img.source = "TILED"
    img.filepath = template
    img.reload()
    img.colorspace_settings.name = "Non-Color"
    sizes = {tile.number: tuple(tile.size) for tile in img.tiles}
    if sorted(sizes) != sorted(tiles) or any(s == (0, 0) for s in sizes.values()):
        raise RuntimeError(f"{template}: tiles {sizes} did not load")
    return img


def image_array(img):
    """The raw pixels of a Blender image as (H, W, 4) float32, rows top first."""
    import numpy as np
    w, h = img.size
    buf = np.empty(w * h * 4, np.float32)
    img.pixels.foreach_get(buf)
    return buf.reshape(h, w, 4)[::-1].copy()


def load_raw(path):
    """Loads an image file with Blender as Non-Color data; returns (H, W, 4) float32 rows top
    first (byte images come back as value / 255, 16-bit PNG as value / 65535)."""
    import bpy
    img = bpy.data.images.load(os.path.abspath(path), check_existing=False)
    img.colorspace_settings.name = "Non-Color"
    try:
        return image_array(img)
    finally:
        bpy.data.images.remove(img)


def save_exr(img, path, verify=True):
    """Saves a float Non-Color image as an RGB 32-bit float, ZIP-compressed OpenEXR with its raw
    values (Image.save_render with the scene's output settings; a Non-Color image gets no
    view transform, whatever the scene's view is), and with verify=True reloads the file and
    requires bit-identical RGB. (Image.save() would write uncompressed RGBA.)"""
    import bpy
    import numpy as np
    expected = image_array(img) if verify else None
    scene = bpy.context.scene
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_mode = "RGB"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    img.save_render(os.path.abspath(path), scene=scene)
    if verify:
        back = load_raw(path)
        if back.shape != expected.shape or not np.array_equal(back[..., :3], expected[..., :3]):
            diff = (np.abs(back[..., :3] - expected[..., :3]).max()
                    if back.shape == expected.shape else "shape")
            raise RuntimeError(f"{path}: EXR round trip is not exact (max diff {diff})")


def emit_plane(out_dir, node_type, output):
    """The scene of the Fac oracles (musgrave_fac_oracle.py, voronoi_distance_oracle.py,
    texture_fac_oracle.py): a plane of side 2, turned and moved so that its object coordinates
    vary in x, y and z, UV-mapped onto the whole square (written as OUT_DIR/mesh.obj), whose
    material emits the `output` of a new node of type `node_type` on the object's coordinates,
    with an active Image Texture to bake into. Returns (node, target): the texture node and the
    Image Texture."""
    import bpy
    import mathutils
    import objio
    reset_scene()
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    ob = bpy.context.active_object
    me = ob.data
    me.transform(mathutils.Matrix.Rotation(0.6, 4, "X") @ mathutils.Matrix.Rotation(0.3, 4, "Y")
                 @ mathutils.Matrix.Translation((0.3, -0.2, 0.1)))
    me.calc_normals_split()
    objio.write_obj(os.path.join(out_dir, "mesh.obj"), objio.mesh_arrays(me))
    setup_cycles(bpy.context.scene)
    mat = bpy.data.materials.new(node_type)
    mat.use_nodes = True
    me.materials.append(mat)
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    coordinates = nodes.new("ShaderNodeTexCoord")
    node = nodes.new(node_type)
    emission = nodes.new("ShaderNodeEmission")
    material_output = nodes.new("ShaderNodeOutputMaterial")
    links.new(coordinates.outputs["Object"], node.inputs["Vector"])
    links.new(node.outputs[output], emission.inputs["Color"])
    links.new(emission.outputs["Emission"], material_output.inputs["Surface"])
    target = nodes.new("ShaderNodeTexImage")
    nodes.active = target
    ob.select_set(True)
    bpy.context.view_layer.objects.active = ob
    return node, target


def bake_emit(target, name, size, path):
    """Bakes EMIT (margin 0) into a new float image NAME (SIZE^2) that the Image Texture node
    `target` holds, and saves it as the EXR at PATH."""
    import bpy
    image = new_float_image(name, size, size)
    target.image = image
    result = bpy.ops.object.bake(type="EMIT", margin=0, use_clear=True,
                                 target="IMAGE_TEXTURES", save_mode="INTERNAL")
    if result != {"FINISHED"}:
        raise RuntimeError(f"bake {name} returned {result}")
    save_exr(image, path)


def largest_differences(out_dir, case, prefixes=("ours", "control")):
    """The largest |difference| of each PREFIX_CASE.exr from blender_CASE.exr in OUT_DIR (their
    first channel), and the range of Blender's: {prefix: difference, "range": [min, max]}."""
    import numpy as np
    theirs = load_raw(os.path.join(out_dir, f"blender_{case}.exr"))[..., 0]
    result = {prefix: float(np.abs(
        load_raw(os.path.join(out_dir, f"{prefix}_{case}.exr"))[..., 0].astype(np.float64)
        - theirs).max()) for prefix in prefixes}
    result["range"] = [float(theirs.min()), float(theirs.max())]
    return result


def fac_oracle_blender(argv, tag, bake, cases):
    """The Blender half of a Fac oracle: argv "bake DIR" runs bake(DIR), "compare DIR" prints
    largest_differences of each of `cases` (names), both as JSON after `tag`."""
    if argv[0] == "bake":
        bake(argv[1])
        print(tag + json.dumps({"baked": True}), flush=True)
    else:
        print(tag + json.dumps({case: largest_differences(argv[1], case) for case in cases}),
              flush=True)


def decode_normals(array):
    """(H, W, >=3) encoded normal map -> (H, W, 3) float64 unit vectors (n = 2c - 1)."""
    import numpy as np
    n = np.asarray(array, dtype=np.float64)[..., :3] * 2.0 - 1.0
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    return n / np.maximum(length, 1e-30)


def angle_deg(a, b):
    """Per-texel angle in degrees between two unit-vector arrays, atan2(|a x b|, a . b)
    (accurate for tiny angles, unlike acos)."""
    import numpy as np
    cross = np.linalg.norm(np.cross(a, b), axis=-1)
    return np.degrees(np.arctan2(cross, np.sum(a * b, axis=-1)))


def erode(mask, texels=1):
    """Keeps the True texels whose (2k+1)^2 neighbourhood is all True; texels within k of the
    image border are dropped."""
    import numpy as np
    out = np.asarray(mask, dtype=bool).copy()
    for _ in range(texels):
        m = out
        inner = np.zeros_like(m)
        inner[1:-1, 1:-1] = True
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                inner[1:-1, 1:-1] &= m[1 + dy:m.shape[0] - 1 + dy, 1 + dx:m.shape[1] - 1 + dx]
        out = inner
    return out


def angle_stats(angles):
    """Median, 90th and 99th percentile, max (degrees), the number over 10 degrees and count of
    a 1-D array of angles."""
    import numpy as np
    angles = np.asarray(angles, dtype=np.float64)
    if angles.size == 0:
        return {"median_deg": None, "p90_deg": None, "p99_deg": None, "max_deg": None,
                "texels": 0}
    return {"median_deg": float(np.median(angles)),
            "p90_deg": float(np.percentile(angles, 90)),
            "p99_deg": float(np.percentile(angles, 99)),
            "max_deg": float(angles.max()),
            "over_10_deg": int((angles > 10.0).sum()),
            "texels": int(angles.size)}


def judge_against_control(label, ours, control, median_limit, control_min, control_what,
                          p99_limit=None, min_texels=1000):
    """Prints one line judging the angle_stats `ours` against Cycles (more than `min_texels`
    texels, median <= `median_limit`, p99 <= `p99_limit` when given) and those of a negative
    control (`control_what`: median > `control_min`); returns whether both pass."""
    ok = (ours["texels"] > min_texels and ours["median_deg"] <= median_limit
          and (p99_limit is None or ours["p99_deg"] <= p99_limit))
    told = control["median_deg"] > control_min
    p99 = f"{ours['p99_deg']:.4f}" + (f" (limit {p99_limit})" if p99_limit is not None else "")
    print(f"{label}: {'ok  ' if ok else 'FAIL'} vs Cycles median {ours['median_deg']:.4f} deg "
          f"(limit {median_limit}), p99 {p99}, max {ours['max_deg']:.3f}, {ours['texels']} "
          f"texels; {'ok  ' if told else 'FAIL'} {control_what} median "
          f"{control['median_deg']:.3f} deg (must exceed {control_min})")
    return ok and told


def fac_oracle_main(doc, script, tag, size, layers, limit, quantity, control_what,
                    sabotage_help, control_min=1e-2):
    """The driver of a Fac oracle (musgrave_fac_oracle.py, voronoi_distance_oracle.py,
    texture_fac_oracle.py; options --cli, --blender, --keep, --sabotage): Blender runs `script`
    to bake blender_CASE.exr (fac_oracle_blender); the CLI bakes the "height" map (SIZE^2,
    margin 0, 1 sample, 32-bit) of each layer of layers(sabotage) = {case: (ours, control)}
    into ours_CASE.exr and control_CASE.exr; Blender compares. Each of ours must be within
    limit(case) of Cycles' `quantity` (the node's output, "Fac" or "Distance"), each control
    (`control_what`: "the next type's") at least `control_min` off. Returns the exit status."""
    import objio
    parser = oracle_parser(doc, blender_help=None)
    parser.add_argument("--sabotage", action="store_true", help=sabotage_help)
    args = parser.parse_args()
    blender = blender_or_skip(args.blender)
    require_executable(args.cli, "error: --cli {} is not an executable file")
    with work_dir(args.keep, f"sgbake_{os.path.splitext(os.path.basename(script))[0]}_") as out:
        if objio.run_blender_result(blender, script, ["bake", out], tag) is None:
            return 1
        for case, pair in layers(args.sabotage).items():
            for prefix, layer in zip(("ours", "control"), pair):
                scene = {"mesh": "mesh.obj", "layers": [layer],
                         "outputs": [{"map": "height", "file": f"{prefix}_{case}.exr",
                                      "size": size, "margin": 0, "samples": 1, "bit_depth": 32}]}
                if not bake_scene_file(args.cli, out, f"{prefix}_{case}", scene):
                    return 1
        stats = objio.run_blender_result(blender, script, ["compare", out], tag)
        if stats is None:
            return 1
        failures = []
        for case, s in stats.items():
            close, told = s["ours"] <= limit(case), s["control"] >= control_min
            print(f"  {case}: {quantity} in [{s['range'][0]:.3f}, {s['range'][1]:.3f}], max "
                  f"|diff| {s['ours']:.2g} (<= {limit(case):g}), {control_what} "
                  f"{s['control']:.3g} (>= {control_min:g}) -> {'ok' if close and told else 'FAIL'}")
            if not close:
                failures.append(f"{case}: the {quantity} differs from Cycles' by {s['ours']:.3g}")
            if not told:
                failures.append(f"{case}: {control_what} {quantity} is within {s['control']:.3g} "
                                "of Cycles' (the control cannot tell them apart)")
        return report(failures)


def bake_scene_file(cli, directory, name, scene):
    """Writes `scene` (a dict) as DIRECTORY/NAME.json and bakes it with `CLI bake` (no
    manifest); returns whether it exited with 0."""
    path = os.path.join(directory, name + ".json")
    with open(path, "w", encoding="ascii") as f:
        json.dump(scene, f)
    proc = run_tool([cli, "bake", path, "--no-manifest"])
    return proc is not None and proc.returncode == 0
