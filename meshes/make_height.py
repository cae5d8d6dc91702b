"""Regenerates meshes/height.png, the height map of the default scene (run from anywhere):

    python3 meshes/make_height.py

A 512 x 512 16-bit grey PNG that tiles seamlessly: an 8 x 8 grid of square plates with
smoothly bevelled edges, separated by grooves, each with a round dome in its middle. Heights are
in [0, 1] (0 = groove floor, 0.75 = plate top, 1 = dome top). Plain Python (zlib), no numpy.
"""

import math
import os
import struct
import zlib

SIZE = 512        # texels per side
TILES = 8         # plates per side
GROOVE = 3        # half-width of the groove floor, texels
BEVEL = 10        # width of the bevel from groove floor to plate top, texels
PLATE = 0.75      # plate height
DOME_RADIUS = 14  # texels
DOME = 0.25       # dome height above the plate


def smoothstep(t):
    t = min(max(t, 0.0), 1.0)
    return t * t * (3.0 - 2.0 * t)


def height(x, y):
    """Height at the centre of texel (x, y), y counted down from the top row."""
    period = SIZE // TILES
    # Position inside the plate, measured from its centre, in texels.
    px = (x + 0.5) % period - period / 2
    py = (y + 0.5) % period - period / 2
    edge = period / 2 - max(abs(px), abs(py))  # distance to the plate's border
    h = PLATE * smoothstep((edge - GROOVE) / BEVEL)
    r = math.hypot(px, py)
    if r < DOME_RADIUS:
        h += DOME * math.sqrt(1.0 - (r / DOME_RADIUS) ** 2)
    return h


def png_chunk(kind, data):
    chunk = kind + data
    return struct.pack(">I", len(data)) + chunk + struct.pack(">I", zlib.crc32(chunk) & 0xFFFFFFFF)


def main():
    rows = []
    for y in range(SIZE):
        values = [round(height(x, y) * 65535) for x in range(SIZE)]
        raw = struct.pack(">%dH" % SIZE, *values)
        # Filter type 1 (Sub): flat plates and linear ramps become runs of equal bytes.
        filtered = bytearray(raw[:2])
        for i in range(2, len(raw)):
            filtered.append((raw[i] - raw[i - 2]) & 0xFF)
        rows.append(b"\x01" + bytes(filtered))
    header = struct.pack(">IIBBBBB", SIZE, SIZE, 16, 0, 0, 0, 0)  # 16-bit greyscale
    png = (b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", header) +
           png_chunk(b"IDAT", zlib.compress(b"".join(rows), 9)) + png_chunk(b"IEND", b""))
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "height.png")
    with open(path, "wb") as out:
        out.write(png)
    print(f"{path}: {SIZE}x{SIZE} 16-bit, {len(png)} bytes")


if __name__ == "__main__":
    main()
