#!/usr/bin/env python3
"""The BlenderMusgraveFacOracle test: the Musgrave Texture's Fac itself against Cycles'.

    python3 tests/blender/musgrave_fac_oracle.py --cli build/src/sgbake [--blender blender]
        [--keep DIR] [--sabotage]

1. Blender builds a plane of side 2, turned and moved so that its object coordinates vary in
   x, y and z, UV-mapped onto the whole square, and for each of SETTINGS and each of the five
   Musgrave types (3D) bakes the node's Fac on the object's coordinates with Cycles (EMIT of
   an Emission whose Color is the Fac, 1 sample, 128^2, margin 0) into blender_S_TYPE.exr; it
   writes mesh.obj.
2. sgbake bakes the "height" map of a "blender-musgrave" volume layer of amplitude 1 with the
   same settings and type (ours_S_TYPE.exr), and the same layer of the next type in TYPES
   (control_S_TYPE.exr, the type not read).
3. Back in Blender (as the EXR reader), the largest |difference| over every texel.

Pass: each of ours within FAC_LIMIT of Cycles' (Cycles computes in float on values up to ~2:
measured 1.0e-6 for fBM and Multifractal, 1.5e-6 for Ridged Multifractal and Hetero Terrain,
1.6e-6 for Hybrid Multifractal); each control at least CONTROL_MIN off. --sabotage bakes ours
with a Gain 10% above the node's (fBM, Multifractal and Hetero Terrain, which have none, keep
theirs), to see the test fail.

Exit status: 0 pass, 1 fail, 2 usage error, 77 Blender is not installed. Takes ~10 s.
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, HERE)
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

SIZE = 128
# Blender's Type -> the scene's "musgrave_type", and the inputs the type reads beyond Scale,
# Detail, Dimension and Lacunarity.
TYPES = {"FBM": ("fbm", ()), "MULTIFRACTAL": ("multifractal", ()),
         "RIDGED_MULTIFRACTAL": ("ridged-multifractal", ("Offset", "Gain")),
         "HYBRID_MULTIFRACTAL": ("hybrid-multifractal", ("Offset", "Gain")),
         "HETERO_TERRAIN": ("hetero-terrain", ("Offset",))}
# The node's inputs: a fractional Detail; a Detail below 1 (Hetero Terrain's fraction reads
# octave 1, Ridged drops it) with a negative Offset and a large Gain.
SETTINGS = (
    {"Scale": 2.0, "Detail": 2.5, "Dimension": 0.9, "Lacunarity": 2.3, "Offset": 0.7,
     "Gain": 1.6},
    {"Scale": 1.7, "Detail": 4.3, "Dimension": 1.4, "Lacunarity": 2.6, "Offset": 0.2,
     "Gain": 5.0},
    {"Scale": 3.0, "Detail": 0.6, "Dimension": 0.4, "Lacunarity": 1.8, "Offset": -0.3,
     "Gain": 3.0},
)
FAC_LIMIT = 5e-6
CONTROL_MIN = 1e-2
RESULT_TAG = "MUSGRAVE_FAC_ORACLE_RESULT "


def name(index, blender_type):
    return f"{index}_{blender_type}"


# ---- Inside Blender: the bakes and the comparison --------------------------------------------

def bake(out_dir):
    """Step 1: mesh.obj and blender_S_TYPE.exr."""
    musgrave, target = bc.emit_plane(out_dir, "ShaderNodeTexMusgrave", "Fac")
    musgrave.musgrave_dimensions = "3D"
    for index, settings in enumerate(SETTINGS):
        for blender_type in TYPES:
            musgrave.musgrave_type = blender_type
            for socket, value in settings.items():
                musgrave.inputs[socket].default_value = value
            case = name(index, blender_type)
            bc.bake_emit(target, case, SIZE, os.path.join(out_dir, f"blender_{case}.exr"))


def blender_main(argv):
    bc.fac_oracle_blender(argv, RESULT_TAG, bake, [
        name(index, blender_type) for index in range(len(SETTINGS)) for blender_type in TYPES])


# ---- The driver ------------------------------------------------------------------------------

def layer(settings, blender_type, gain_factor=1.0):
    """The "blender-musgrave" volume layer of the node's `settings` and type `blender_type`
    (its Gain times `gain_factor`), amplitude 1."""
    musgrave_type, inputs = TYPES[blender_type]
    values = {"type": "volume", "function": "blender-musgrave", "amplitude": 1.0,
              "frequency": settings["Scale"], "musgrave_type": musgrave_type,
              "detail": settings["Detail"], "dimension": settings["Dimension"],
              "lacunarity": settings["Lacunarity"]}
    for socket in inputs:
        values[socket.lower()] = settings[socket] * (gain_factor if socket == "Gain" else 1.0)
    return values


def layers(sabotage):
    """Each case's layer and its control's: the same settings with the next type in TYPES."""
    types = list(TYPES)
    return {name(index, blender_type): (
        layer(settings, blender_type, 1.1 if sabotage else 1.0),
        layer(settings, types[(i + 1) % len(types)]))
        for index, settings in enumerate(SETTINGS) for i, blender_type in enumerate(types)}


def main():
    return bc.fac_oracle_main(
        __doc__, os.path.abspath(__file__), RESULT_TAG, SIZE, layers, lambda case: FAC_LIMIT,
        "Fac", "the next type's", "bake ours with a Gain 10%% above the node's", CONTROL_MIN)


if __name__ == "__main__":
    objio.run_script(blender_main, main)
