"""Compares sgbake's maps with Cycles' bakes, texel by texel (runs inside Blender).

    blender -b --factory-startup --python-exit-code 1 \\
        --python tests/blender/bake_compare.py -- CASES_DIR [RESULTS_JSON]

Blender is used only as an image reader here (bpy.data.images.load, Non-Color, raw
image.pixels) plus numpy: the plain python3 that runs the test drivers has neither an EXR reader
nor numpy. CASES_DIR is what bake_scene.py wrote (cases.json, NAME/blender_*.exr) with the
sgbake outputs that bake_oracle.py added next to them. For each case, for every file present:

  ours_convert.exr   `sgbake convert --from object --to tangent blender_object.exr`
  ours_bake.exr      `sgbake bake --height ... --map tangent-normal` (command-line form)
  ours_bake_json.exr `sgbake bake scene.json` (the same bake described as JSON)
  ours_bake_x2.exr   the same bake with twice the height scale (a negative control)
  ours_bake_bump_node.exr  the bake with --height-gradient bump-node (heights differenced
                     as Cycles' Bump node does)
  ours_bake_blended.exr  a Box-projection case's bump-node bake with sgbake's own triplanar
                     (projection "blended") instead (a negative control)
  ours_bake_full_strength.exr  a case with a Bump Strength: its bump-node bake at Strength 1
                       (a negative control)
  ours_bake_unmapped.exr  a mapped case's bump-node bake without its "mapping" (a negative
                     control)
  ours_bake_on_object.exr  a case with a texture on UV coordinates: its bump-node bake with the
                     texture read at the object's coordinates instead (a negative control)
  ours_bake_swapped.exr, ours_nmap_swapped.exr  a Sphere- or Tube-projection case's bake
                     with the other wrap (a negative control)
  ours_bake_unscaled.exr  an object-space displacement case's bump-node bake with the
                     node's Scale in world units (a negative control)
  ours_bake_unremapped.exr  a remapped case's bump-node bake without its "remap" (a negative
                     control)
  ours_mask.exr      `sgbake bake --map mask`
  ours_nmap_tangent.exr, ours_nmap_object.exr   a normal-map case's scene (normal layer,
                     tangent- and object-normal outputs), against Blender's tangent and
                     object bakes
  ours_nmap_flags.exr  the same tangent-normal bake from --normal flags (Strength 1 cases)
  ours_nmap_weak.exr   the scene's tangent-normal bake at 0.9 x Strength (negative control)
  ours_nmap_uv.exr     a Box-projected normal map's case: the map read through the UV map
                       instead (negative control)
  ours_bake_object_space.exr, ours_nmap_object_space.exr   a transformed case's bake
                       without its transform (in object space: a negative control)
  ours_nmap_sum.exr    a chain case's bake with the bump added to the normal map's surface
                       gradient instead of stacked on its normal (negative control)

it computes, over the texels Blender's EMIT mask covers, minus those within one texel of an
island border (3 x 3 erosion: texels whose centres straddle a UV edge may fall in different
triangles for Blender and us):
  - the angle between the decoded normals (n = 2c - 1, normalised), as median / 90th and 99th
    percentile / max in degrees and the number of texels compared;
  - the same for our map with its green channel flipped (negative control: a wrong bitangent
    must be visible);
  - outside: the largest |difference| from the expected background over texels at least two
    texels away from any covered texel (convert keeps its input there; bake writes
    (0.5, 0.5, 1));
  - json_vs_flags: largest |difference| between the JSON-scene and the command-line bake
    (normal-map cases: ours_nmap_flags against ours_nmap_tangent);
  - mask: texels where our coverage (> 0.5) and Blender's differ, and Blender's covered count;
  - tilt: the median/p99 angle of Blender's tangent-space normal from +Z (how strong the bump
    is; the scale control is meaningless on a flat map).
Results go to RESULTS_JSON (default CASES_DIR/results.json) as {case: {check: stats}}; the
driver applies the thresholds. Exit status 1 only when Blender's own files are missing.
"""

import json
import os
import sys

import numpy as np

sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)

FAR = 2  # "outside" texels are at least this many texels from any covered texel


def dilate(mask, texels):
    return ~bc.erode(np.pad(~mask, texels, constant_values=True), texels)[texels:-texels,
                                                                          texels:-texels]


def compare_normals(ours, ref, region):
    """Angle statistics over `region` between two encoded normal maps, also with ours' green
    channel flipped."""
    a, b = bc.decode_normals(ours), bc.decode_normals(ref)
    angles = bc.angle_deg(a, b)[region]
    flipped = a.copy()
    flipped[..., 1] *= -1.0
    stats = bc.angle_stats(angles)
    stats["flipped_green"] = bc.angle_stats(bc.angle_deg(flipped, b)[region])
    # Where the worst texel is (file row, column), to look at it.
    if angles.size:
        rows, cols = np.nonzero(region)
        worst = int(np.argmax(angles))
        stats["worst_at"] = [int(cols[worst]), int(rows[worst])]
    return stats


def load_if(path):
    return bc.load_raw(path) if os.path.exists(path) else None


def compare_case(entry):
    d = entry["dir"]
    ref_tangent = bc.load_raw(os.path.join(d, "blender_tangent.exr"))
    ref_object = bc.load_raw(os.path.join(d, "blender_object.exr"))
    covered = bc.load_raw(os.path.join(d, "blender_mask.exr"))[..., 0] > 0.5
    inner = bc.erode(covered, 1)
    outside = ~dilate(covered, FAR)
    out = {"size": list(ref_tangent.shape[:2]), "covered": int(covered.sum()),
           "compared": int(inner.sum())}
    tilt = bc.angle_deg(bc.decode_normals(ref_tangent), np.array([0.0, 0.0, 1.0]))[inner]
    out["tilt"] = bc.angle_stats(tilt)

    convert = load_if(os.path.join(d, "ours_convert.exr"))
    if convert is not None:
        if convert.shape != ref_tangent.shape:
            out["convert"] = {"error": f"size {convert.shape[:2]} != {ref_tangent.shape[:2]}"}
        else:
            out["convert"] = compare_normals(convert, ref_tangent, inner)
            diff = np.abs(convert[..., :3] - ref_object[..., :3])[outside]
            out["convert"]["outside_max_abs"] = float(diff.max()) if diff.size else 0.0

    bake = None
    for key, name in (("bake", "ours_bake.exr"), ("bake_json", "ours_bake_json.exr"),
                      ("bake_x2", "ours_bake_x2.exr"),
                      ("bake_bump_node", "ours_bake_bump_node.exr"),
                      ("bake_blended", "ours_bake_blended.exr"),
                      ("bake_unmapped", "ours_bake_unmapped.exr"),
                      ("bake_on_object", "ours_bake_on_object.exr"),
                      ("bake_swapped", "ours_bake_swapped.exr"),
                      ("bake_unscaled", "ours_bake_unscaled.exr"),
                      ("bake_full_strength", "ours_bake_full_strength.exr"),
                      ("bake_unremapped", "ours_bake_unremapped.exr"),
                      ("bake_object_space", "ours_bake_object_space.exr")):
        img = load_if(os.path.join(d, name))
        if img is None:
            continue
        if img.shape != ref_tangent.shape:
            out[key] = {"error": f"size {img.shape[:2]} != {ref_tangent.shape[:2]}"}
            continue
        out[key] = compare_normals(img, ref_tangent, inner)
        background = np.abs(img[..., :3] - np.array([0.5, 0.5, 1.0], np.float32))[outside]
        out[key]["outside_max_abs"] = float(background.max()) if background.size else 0.0
        if key == "bake":
            bake = img
        elif key == "bake_json" and bake is not None:
            out[key]["json_vs_flags_max_abs"] = float(np.abs(img[..., :3] - bake[..., :3]).max())

    refs = {"tangent": ref_tangent, "object": ref_object}
    nmap = None
    for key, name, space in (("nmap_tangent", "ours_nmap_tangent.exr", "tangent"),
                             ("nmap_object", "ours_nmap_object.exr", "object"),
                             ("nmap_flags", "ours_nmap_flags.exr", "tangent"),
                             ("nmap_weak", "ours_nmap_weak.exr", "tangent"),
                             ("nmap_uv", "ours_nmap_uv.exr", "tangent"),
                             ("nmap_swapped", "ours_nmap_swapped.exr", "tangent"),
                             ("nmap_sum", "ours_nmap_sum.exr", "tangent"),
                             ("nmap_bump_node", "ours_nmap_bump_node.exr", "tangent"),
                             ("nmap_object_space", "ours_nmap_object_space.exr", "tangent")):
        img = load_if(os.path.join(d, name))
        if img is None:
            continue
        ref = refs[space]
        if img.shape != ref.shape:
            out[key] = {"error": f"size {img.shape[:2]} != {ref.shape[:2]}"}
            continue
        out[key] = compare_normals(img, ref, inner)
        if space == "tangent":
            background = np.abs(img[..., :3] - np.array([0.5, 0.5, 1.0], np.float32))[outside]
            out[key]["outside_max_abs"] = float(background.max()) if background.size else 0.0
        if key == "nmap_tangent":
            nmap = img
        elif key == "nmap_flags" and nmap is not None:
            out[key]["json_vs_flags_max_abs"] = float(np.abs(img[..., :3] - nmap[..., :3]).max())

    mask = load_if(os.path.join(d, "ours_mask.exr"))
    if mask is not None:
        if mask.shape != ref_tangent.shape:
            out["mask"] = {"error": f"size {mask.shape[:2]} != {ref_tangent.shape[:2]}"}
        else:
            ours = mask[..., 0] > 0.5
            out["mask"] = {"mismatched": int(np.count_nonzero(ours != covered)),
                           "ours_only": int(np.count_nonzero(ours & ~covered)),
                           "blender_only": int(np.count_nonzero(covered & ~ours)),
                           "covered": int(covered.sum())}
    return out


def main(argv):
    cases_dir = argv[0]
    results_path = argv[1] if len(argv) > 1 else os.path.join(cases_dir, "results.json")
    with open(os.path.join(cases_dir, "cases.json"), encoding="ascii") as f:
        entries = json.load(f)
    results = {}
    for entry in entries:
        results[entry["name"]] = compare_case(entry)
        print("COMPARE " + entry["name"] + " " + json.dumps(results[entry["name"]]), flush=True)
    with open(results_path, "w", encoding="ascii") as f:
        json.dump(results, f, indent=1)


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--") + 1:])
