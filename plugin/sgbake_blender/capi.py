"""ctypes binding of libsgbake's C ABI (include/sgbake/sgbake.h), for the Blender add-on.

No bpy here: this module only finds and loads the shared library, declares the signatures of
the functions the add-on calls and moves numpy arrays across, so it also works from a plain
Python with numpy (scripts, tests).

    lib = capi.load_library()                       # or load_library("/path/libsgbake.so")
    rgba = capi.bake_map(lib, scene, positions, face_start, corner_vertex, corner_normals,
                         [uvs], {"Bumps": (pixels, width, height, channels)})

Why the checks below: the C side validates everything it can see, but it receives bare
pointers plus the counts we pass. Array lengths it cannot know (the normals and UVs of #C
corners, the pixels of a W x H x C image, the output buffer) are checked here, before the call,
so that a wrong array is a Python exception and never a read past the end of a buffer.
"""

import ctypes
import ctypes.util
import json
import os

import numpy as np

LIBRARY_ENV = "SGBAKE_LIBRARY"
LIBRARY_FILE = "libsgbake.so"
ERROR_BUFFER_SIZE = 1024
CANCELLED = 3  # SGBAKE_CANCELLED

_float_p = ctypes.POINTER(ctypes.c_float)
_uint32_p = ctypes.POINTER(ctypes.c_uint32)


class SgbakeError(Exception):
    """A failure reported by libsgbake, or detected before calling it.

    `status` is the library's status code (1 internal error, 2 bad input) or None when the
    library could not be loaded or an argument was refused before the call. str() is the
    one-line message."""

    def __init__(self, message, status=None):
        super().__init__(message)
        self.status = status


class SgbakeCancelled(SgbakeError):
    """The bake was stopped through its Progress (cancel set): not an error of the input."""


class Progress(ctypes.Structure):
    """struct sgbake_progress: the library writes `fraction` (0 to 1) while it bakes; set
    `cancel` to 1 from another thread to stop the bake (bake_map then raises SgbakeCancelled).
    ctypes releases the GIL during the call, so a UI thread can poll and cancel meanwhile."""
    _fields_ = [("fraction", ctypes.c_float), ("cancel", ctypes.c_int32)]


class Mesh(ctypes.Structure):
    """struct sgbake_mesh."""
    _fields_ = [
        ("positions", _float_p),
        ("num_vertices", ctypes.c_size_t),
        ("face_start", _uint32_p),
        ("num_faces", ctypes.c_size_t),
        ("corner_vertex", _uint32_p),
        ("corner_normals", _float_p),
        ("corner_uvs", ctypes.POINTER(_float_p)),
        ("num_uv_sets", ctypes.c_size_t),
        ("num_corners", ctypes.c_size_t),
        ("face_flat", ctypes.POINTER(ctypes.c_uint8)),
        ("auto_smooth", ctypes.c_int),
        ("face_material", _uint32_p),
    ]


# The oldest library whose struct sgbake_mesh is Mesh above (0.6.0 appended face_material): an
# older one would read a shorter struct, a newer one with the same major and minor version the
# same.
MIN_LIBRARY_VERSION = (0, 6)


class Image(ctypes.Structure):
    """struct sgbake_image."""
    _fields_ = [
        ("name", ctypes.c_char_p),
        ("pixels", _float_p),
        ("width", ctypes.c_int32),
        ("height", ctypes.c_int32),
        ("channels", ctypes.c_int32),
    ]


def candidate_paths(path=None, path_source="the given path"):
    """The places load_library tries, in order, as (description, path or library name,
    explicit) triples: the given path (described as path_source), $SGBAKE_LIBRARY, libsgbake.so
    in this file's folder, the library of the installation this add-on came from (the
    installed_library.py that `cmake --install` writes beside it), then the system's search
    (ctypes.util.find_library, which runs only when the earlier places had nothing)."""
    if path:
        yield path_source, path, True
    if os.environ.get(LIBRARY_ENV):
        yield f"${LIBRARY_ENV}", os.environ[LIBRARY_ENV], True
    here = os.path.dirname(os.path.realpath(__file__))  # through a symbolic link to the add-on
    yield "beside the add-on", os.path.join(here, LIBRARY_FILE), False
    try:
        from . import installed_library
    except ImportError:  # the add-on from the source tree: no installation
        installed_library = None
    if installed_library is not None:
        yield ("the add-on's installation",
               os.path.normpath(os.path.join(here, installed_library.LIBRARY)), False)
    system = ctypes.util.find_library("sgbake")
    if system:
        yield "the system library path", system, False


def _declare(lib):
    """Sets argtypes/restype of the functions used here (ctypes would otherwise pass size_t
    arguments as 32-bit ints and truncate pointers returned as int)."""
    lib.sgbake_version.argtypes = []
    lib.sgbake_version.restype = ctypes.c_char_p
    lib.sgbake_bake_map.argtypes = [
        ctypes.c_char_p,            # scene_json
        ctypes.POINTER(Mesh),       # mesh
        ctypes.POINTER(Image),      # images
        ctypes.c_size_t,            # num_images
        ctypes.c_int,               # threads
        ctypes.POINTER(Progress),   # progress (may be NULL)
        _float_p,                   # out_rgba
        ctypes.c_size_t,            # out_floats
        ctypes.c_char_p,            # error_buf
        ctypes.c_size_t,            # error_buf_size
    ]
    lib.sgbake_bake_map.restype = ctypes.c_int
    return lib


def load_library(path=None, path_source="the given path"):
    """Loads libsgbake from the first candidate that exists (see candidate_paths) and returns
    the ctypes.CDLL with its functions declared. An explicit path or $SGBAKE_LIBRARY that
    cannot be loaded is an error (it is not silently skipped for a library found elsewhere).
    Raises SgbakeError naming every place tried when none works."""
    tried = []
    for where, candidate, explicit in candidate_paths(path, path_source):
        if os.sep in candidate and not os.path.exists(candidate):
            if explicit:
                raise SgbakeError(f"cannot load libsgbake: {candidate} ({where}) does not exist")
            tried.append(candidate)
            continue
        try:
            lib = ctypes.CDLL(candidate)
        except OSError as exc:
            raise SgbakeError(f"cannot load libsgbake from {candidate} ({where}): {exc}") from None
        if not hasattr(lib, "sgbake_bake_map"):
            raise SgbakeError(f"{candidate} ({where}) has no sgbake_bake_map: "
                              "it is an older libsgbake or another library")
        lib = _declare(lib)
        found = version(lib)
        try:
            numbers = tuple(int(part) for part in found.split(".")[:2])
        except ValueError:
            numbers = (0, 0)
        if numbers < MIN_LIBRARY_VERSION:
            wanted = ".".join(str(n) for n in MIN_LIBRARY_VERSION)
            raise SgbakeError(f"{candidate} ({where}) is libsgbake {found}, older than the "
                              f"{wanted} this add-on passes meshes to (install the libsgbake "
                              "built with this add-on)")
        return lib
    raise SgbakeError("cannot find libsgbake: set the library path in the add-on's preferences "
                      f"or ${LIBRARY_ENV}, or put {LIBRARY_FILE} beside the add-on (tried "
                      f"{', '.join(tried) or 'nothing'} and the system library path)")


def version(lib):
    """The library's version string, e.g. "0.2.0"."""
    return lib.sgbake_version().decode("utf-8", "replace")


def _array(values, dtype, name, width=1):
    """`values` as a contiguous 1-D array of `dtype`; its length must be a multiple of width."""
    array = np.ascontiguousarray(values, dtype=dtype).reshape(-1)
    if array.size % width:
        raise SgbakeError(f"{name} has {array.size} values, not a multiple of {width}")
    return array


def _pointer(array, pointer_type):
    return array.ctypes.data_as(pointer_type)


def output_size(scene):
    """(width, height) of the scene's single output: "size", or "width" and "height", each
    1024 by default as in a scene file."""
    outputs = scene.get("outputs")
    if not isinstance(outputs, list) or len(outputs) != 1 or not isinstance(outputs[0], dict):
        raise SgbakeError("the scene must have exactly one output")
    output = outputs[0]
    size = output.get("size", 1024)
    width, height = output.get("width", size), output.get("height", size)
    if not all(isinstance(v, int) and v >= 1 for v in (width, height)):
        raise SgbakeError(f"the output's size must be positive integers, not {width} x {height}")
    return width, height


def _image_entry(name, image):
    """(pixels as float32, width, height, channels) from ndarray (H, W[, C]) rows bottom first,
    or from a tuple (flat pixels, width, height, channels)."""
    if isinstance(image, tuple):
        pixels, width, height, channels = image
        pixels = _array(pixels, np.float32, f"image {name!r}")
    else:
        array = np.asarray(image)
        if array.ndim == 2:
            array = array[..., None]
        if array.ndim != 3:
            raise SgbakeError(f"image {name!r} must be H x W x C, not shape {array.shape}")
        height, width, channels = array.shape
        pixels = _array(array, np.float32, f"image {name!r}")
    if pixels.size != width * height * channels:
        raise SgbakeError(f"image {name!r} has {pixels.size} values, expected "
                          f"{width} x {height} x {channels}")
    return pixels, int(width), int(height), int(channels)


def bake_map(lib, scene, positions, face_start, corner_vertex, corner_normals, uv_sets,
             images=None, threads=0, progress=None, face_flat=None, auto_smooth=False,
             face_material=None):
    """Bakes one map with sgbake_bake_map and returns its pixels.

    scene           dict: a scene as for `sgbake bake SCENE.json` without "mesh", with one
                    output that has no "file", "format" or "bit_depth"; layer "image" keys
                    name entries of `images`.
    positions       #V x 3 vertex positions (object space).
    face_start      #F + 1 corner offsets (Blender: polygons' loop_start, #C appended).
    corner_vertex   #C vertex indices.
    corner_normals  #C x 3 unit corner normals, or None for smooth normals computed by sgbake.
    uv_sets         list of #C x 2 UV arrays; set 0 is the one tangent frames are built on;
                    a scene's "uv": N reads uv_sets[N].
    images          dict name -> ndarray H x W x C (or H x W) rows bottom first, or
                    name -> (flat pixels, width, height, channels).
    threads         maximum number of threads, 0 = all cores (same result for every value).
    progress        a Progress to follow or cancel the bake from another thread, or None.
    face_flat       #F flags, nonzero for a flat-shaded face (Blender: not use_smooth), or
                    None: every face smooth. Flat faces are shaded per triangle, as Cycles does,
                    unless auto_smooth.
    auto_smooth     Blender's Auto Smooth (mesh.use_auto_smooth): every face, flat ones
                    included, is shaded with its corner normals.
    face_material   #F material indices (Blender: polygons' material_index), or None: every
                    face material 0. A layer's "material": N applies to material N's faces.

    Returns a float32 array of width * height * 4 values (RGBA, rows bottom first: the layout
    of Blender's Image.pixels). Raises SgbakeError on any failure, SgbakeCancelled when
    `progress.cancel` stopped the bake.
    """
    width, height = output_size(scene)
    # Every array handed to C is bound to a local name below, so it lives until the call ends.
    positions = _array(positions, np.float32, "positions", 3)
    face_start = _array(face_start, np.uint32, "face_start")
    corner_vertex = _array(corner_vertex, np.uint32, "corner_vertex")
    num_corners = corner_vertex.size
    num_faces = face_start.size - 1
    if num_faces < 0:
        raise SgbakeError("face_start needs #F + 1 entries (at least one)")
    if corner_normals is not None:
        corner_normals = _array(corner_normals, np.float32, "corner_normals", 3)
        if corner_normals.size != 3 * num_corners:
            raise SgbakeError(f"corner_normals has {corner_normals.size // 3} normals for "
                              f"{num_corners} corners")
    if face_flat is not None:
        face_flat = _array(face_flat, np.uint8, "face_flat")
        if face_flat.size != num_faces:
            raise SgbakeError(f"face_flat has {face_flat.size} flags for {num_faces} faces")
    if face_material is not None:
        face_material = _array(face_material, np.uint32, "face_material")
        if face_material.size != num_faces:
            raise SgbakeError(f"face_material has {face_material.size} indices for {num_faces} "
                              "faces")
    uv_arrays = [_array(uv, np.float32, f"uv set {i}", 2) for i, uv in enumerate(uv_sets)]
    for i, uv in enumerate(uv_arrays):
        if uv.size != 2 * num_corners:
            raise SgbakeError(f"uv set {i} has {uv.size // 2} UVs for {num_corners} corners")
    uv_pointers = (_float_p * max(len(uv_arrays), 1))(
        *[_pointer(uv, _float_p) for uv in uv_arrays])

    mesh = Mesh(positions=_pointer(positions, _float_p), num_vertices=positions.size // 3,
                face_start=_pointer(face_start, _uint32_p), num_faces=num_faces,
                corner_vertex=_pointer(corner_vertex, _uint32_p),
                corner_normals=(_pointer(corner_normals, _float_p)
                                if corner_normals is not None else None),
                corner_uvs=uv_pointers, num_uv_sets=len(uv_arrays), num_corners=num_corners,
                face_flat=(_pointer(face_flat, ctypes.POINTER(ctypes.c_uint8))
                           if face_flat is not None else None),
                auto_smooth=1 if auto_smooth else 0,
                face_material=(_pointer(face_material, _uint32_p)
                               if face_material is not None else None))

    entries = [(name.encode("utf-8"),) + _image_entry(name, image)
               for name, image in (images or {}).items()]
    image_structs = (Image * max(len(entries), 1))(
        *[Image(name=encoded, pixels=_pointer(pixels, _float_p), width=w, height=h, channels=c)
          for encoded, pixels, w, h, c in entries])

    out = np.empty(width * height * 4, np.float32)
    error = ctypes.create_string_buffer(ERROR_BUFFER_SIZE)
    scene_text = json.dumps(scene).encode("utf-8")
    status = lib.sgbake_bake_map(scene_text, ctypes.byref(mesh), image_structs, len(entries),
                                 int(threads),
                                 ctypes.byref(progress) if progress is not None else None,
                                 _pointer(out, _float_p), out.size, error, ctypes.sizeof(error))
    if status != 0:
        message = error.value.decode("utf-8", "replace") or f"sgbake_bake_map returned {status}"
        raise (SgbakeCancelled if status == CANCELLED else SgbakeError)(message, status)
    return out
