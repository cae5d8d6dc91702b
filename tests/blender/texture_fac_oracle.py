#!/usr/bin/env python3
"""The BlenderTextureFacOracle test: the Gradient and Magic Textures' Fac, and the Noise and
Musgrave Textures' of Dimensions 1D, 2D and 4D, against Cycles'.

    python3 tests/blender/texture_fac_oracle.py --cli build/src/sgbake [--blender blender]
        [--keep DIR] [--sabotage]

1. Blender builds the Fac oracles' plane (bake_common.emit_plane: side 2, turned and moved so
   that its object coordinates vary in x, y and z) and for each of CASES bakes the node's Fac
   on the object's coordinates with Cycles (EMIT of an Emission whose Color is the Fac, 1
   sample, 128^2, margin 0) into blender_CASE.exr: the Gradient Texture of each of its seven
   types, the Magic Texture at a few Depths, Scales and Distortions, the Noise Texture
   (NOISE_SETTINGS) and the Musgrave Texture (MUSGRAVE_SETTINGS) of Dimensions 1D, 2D and 4D.
2. sgbake bakes the "height" map of the "blender-gradient" or "blender-magic" volume layer of
   amplitude 1 with the same settings (ours_CASE.exr; "blender-noise" and "blender-musgrave"
   with their "dimensions" and "w"), and the layer of the case's neighbour (control_CASE.exr:
   the next Gradient Type; the Magic Texture one Depth deeper, or shallower at 10; the Noise and
   Musgrave Textures' W 0.5 further in 1D and 4D, Dimensions 3D for 2D).
3. Back in Blender (as the EXR reader), the largest |difference| over every texel.

Pass: each of ours within FAC_LIMIT of Cycles' (STRONG_LIMIT for a Magic Texture of Distortion
beyond STRONG_DISTORTION: Cycles computes in float, and each of its steps multiplies the
rounding before it by up to 3|Distortion|; MUSGRAVE_LIMIT for the Musgrave Texture;
NOISE_DISTORTED_LIMIT for a distorted Noise Texture); each control at least CONTROL_MIN off.
--sabotage bakes ours with an amplitude of 1 - 1e-4, to see the test fail.

Exit status: 0 pass, 1 fail, 2 usage error, 77 Blender is not installed. Takes ~30 s.
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, HERE)
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

SIZE = 128
# Blender's Gradient Type -> the scene's "gradient_type", in the order whose next is the control.
GRADIENT_TYPES = {"LINEAR": "linear", "QUADRATIC": "quadratic", "EASING": "easing",
                  "DIAGONAL": "diagonal", "SPHERICAL": "spherical",
                  "QUADRATIC_SPHERE": "quadratic-sphere", "RADIAL": "radial"}
# The Magic Texture's settings: (Depth, Scale, Distortion): no steps and a Distortion that only
# divides, a few steps, every step with a Distortion below 1, a negative one, and a strong one.
MAGIC_SETTINGS = ((0, 1.3, 1.6), (2, 1.5, 1.0), (10, 1.1, 0.7), (4, 0.9, -0.9), (5, 0.8, 2.0))
# The Noise Texture of Dimensions other than 3D: (Dimensions, W, Scale, Detail, Roughness,
# Distortion). 1D reads W alone (one Fac over the plane); 2D (x, y); 4D (x, y, z, W), without
# and with distortion. The control: W moved by 0.5 (1D, 4D), or Dimensions 3D (2D).
NOISE_SETTINGS = (("1D", 0.73, 1.7, 4.0, 0.6, 0.5), ("2D", 0.0, 3.1, 2.5, 0.6, 0.4),
                  ("4D", 0.37, 2.3, 3.0, 0.5, 0.0), ("4D", -1.2, 1.9, 1.5, 0.7, 1.1))
# The Musgrave Texture of Dimensions other than 3D: (Dimensions, Type, W), with Scale 2, Detail
# 2.5, Dimension 0.9, Lacunarity 2.3, Offset 0.7, Gain 1.6. The control as the Noise's.
MUSGRAVE_SETTINGS = (("1D", "HYBRID_MULTIFRACTAL", 0.9), ("2D", "FBM", 0.0),
                     ("4D", "RIDGED_MULTIFRACTAL", 0.6), ("4D", "HETERO_TERRAIN", -0.4))
MUSGRAVE_INPUTS = {"Scale": 2.0, "Detail": 2.5, "Dimension": 0.9, "Lacunarity": 2.3,
                   "Offset": 0.7, "Gain": 1.6}
MUSGRAVE_TYPES = {"FBM": "fbm", "RIDGED_MULTIFRACTAL": "ridged-multifractal",
                  "HYBRID_MULTIFRACTAL": "hybrid-multifractal", "HETERO_TERRAIN": "hetero-terrain"}
FAC_LIMIT = 2e-6
# Each step multiplies the errors of the values before it by up to 3|Distortion|: with
# Distortion 2 and Depth 5 Cycles' float Fac is 1.2e-5 off ours (a float32 copy of the steps
# differs from a double one by 1.3e-5 there; the median difference is 1.8e-7).
STRONG_DISTORTION, STRONG_LIMIT = 1.7, 2e-5
# Cycles computes the Musgrave Texture in float on values up to ~2 (as musgrave_fac_oracle.py).
MUSGRAVE_LIMIT = 5e-6
# Cycles' distortion reads noise at p plus offsets of 100 to 200, where a float's step is 7.6e-6
# to 1.5e-5: its Fac moves by up to that times the noise's slopes (~2) times the Distortion
# (measured: 9.5e-6 at Distortion 0.4 in 2D, 1.8e-5 at 1.1 in 4D; 3.6e-7 without).
NOISE_DISTORTED_LIMIT = 4e-5
CONTROL_MIN = 1e-2
RESULT_TAG = "TEXTURE_FAC_ORACLE_RESULT "


def gradient_layer(blender_type):
    return {"function": "blender-gradient", "gradient_type": GRADIENT_TYPES[blender_type]}


def magic_layer(depth, scale, distortion):
    return {"function": "blender-magic", "depth": depth, "frequency": scale,
            "distortion": distortion}


def with_dimensions(values, dimensions, w):
    """A layer's `values` with the node's Dimensions and (1D, 4D) W."""
    values = dict(values, dimensions=dimensions)
    if dimensions in ("1D", "4D"):
        values["w"] = w
    return values


def noise_layer(dimensions, w, scale, detail, roughness, distortion):
    return with_dimensions({"function": "blender-noise", "frequency": scale, "detail": detail,
                            "roughness": roughness, "distortion": distortion}, dimensions, w)


def musgrave_layer(dimensions, blender_type, w):
    i = MUSGRAVE_INPUTS
    values = {"function": "blender-musgrave", "frequency": i["Scale"], "detail": i["Detail"],
              "dimension": i["Dimension"], "lacunarity": i["Lacunarity"],
              "musgrave_type": MUSGRAVE_TYPES[blender_type]}
    if blender_type != "FBM":
        values["offset"] = i["Offset"]
    if blender_type in ("RIDGED_MULTIFRACTAL", "HYBRID_MULTIFRACTAL"):
        values["gain"] = i["Gain"]
    return with_dimensions(values, dimensions, w)


def control_of(dimensions, w):
    """The control's Dimensions and W: W moved by 0.5 where it is read, else 3D."""
    return (dimensions, w + 0.5) if dimensions in ("1D", "4D") else ("3D", w)


def cases():
    """name -> (the node's type, its properties, its inputs, sgbake's layer, the control's, the
    limit on its difference from Cycles')."""
    result = {}
    types = list(GRADIENT_TYPES)
    for i, blender_type in enumerate(types):
        result[f"gradient_{blender_type}"] = (
            "ShaderNodeTexGradient", {"gradient_type": blender_type}, {},
            gradient_layer(blender_type), gradient_layer(types[(i + 1) % len(types)]), FAC_LIMIT)
    for depth, scale, distortion in MAGIC_SETTINGS:
        neighbour = depth + 1 if depth < 10 else depth - 1
        result[f"magic_{depth}_{scale}_{distortion}"] = (
            "ShaderNodeTexMagic", {"turbulence_depth": depth},
            {"Scale": scale, "Distortion": distortion},
            magic_layer(depth, scale, distortion), magic_layer(neighbour, scale, distortion),
            STRONG_LIMIT if abs(distortion) > STRONG_DISTORTION else FAC_LIMIT)
    for dimensions, w, scale, detail, roughness, distortion in NOISE_SETTINGS:
        rest = (scale, detail, roughness, distortion)
        result[f"noise_{dimensions}_{w}_{distortion}"] = (
            "ShaderNodeTexNoise", {"noise_dimensions": dimensions},
            {"W": w, "Scale": scale, "Detail": detail, "Roughness": roughness,
             "Distortion": distortion},
            noise_layer(dimensions, w, *rest), noise_layer(*control_of(dimensions, w), *rest),
            NOISE_DISTORTED_LIMIT if distortion else FAC_LIMIT)
    for dimensions, blender_type, w in MUSGRAVE_SETTINGS:
        control_dimensions, control_w = control_of(dimensions, w)
        result[f"musgrave_{dimensions}_{blender_type}"] = (
            "ShaderNodeTexMusgrave",
            {"musgrave_dimensions": dimensions, "musgrave_type": blender_type},
            dict(MUSGRAVE_INPUTS, W=w), musgrave_layer(dimensions, blender_type, w),
            musgrave_layer(control_dimensions, blender_type, control_w), MUSGRAVE_LIMIT)
    return result


# ---- Inside Blender: the bakes and the comparison --------------------------------------------

def bake(out_dir):
    """Step 1: mesh.obj and blender_CASE.exr (one plane and material per texture)."""
    planes = {}
    for case, (node_type, properties, inputs, _, _, _) in cases().items():
        if node_type not in planes:
            planes = {node_type: bc.emit_plane(out_dir, node_type, "Fac")}
        node, target = planes[node_type]
        for key, value in properties.items():
            setattr(node, key, value)
        for socket, value in inputs.items():
            node.inputs[socket].default_value = value
        bc.bake_emit(target, case, SIZE, os.path.join(out_dir, f"blender_{case}.exr"))


def blender_main(argv):
    bc.fac_oracle_blender(argv, RESULT_TAG, bake, cases())


# ---- The driver ------------------------------------------------------------------------------

def main():
    amplitude = {False: 1.0, True: 1.0 - 1e-4}
    return bc.fac_oracle_main(
        __doc__, os.path.abspath(__file__), RESULT_TAG, SIZE,
        lambda sabotage: {case: (dict(ours, type="volume", amplitude=amplitude[sabotage]),
                                 dict(control, type="volume", amplitude=1.0))
                          for case, (_, _, _, ours, control, _) in cases().items()},
        lambda case: cases()[case][-1], "Fac", "its neighbour's",
        "bake ours with an amplitude of 1 - 1e-4", CONTROL_MIN)


if __name__ == "__main__":
    objio.run_script(blender_main, main)
