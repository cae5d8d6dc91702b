"""sgbake for Blender: bakes tangent-space and object-space normal maps, heights, derivatives,
surface gradients, tangent frames and masks of the active mesh object with libsgbake, inside
Blender and without Cycles.

The add-on moves arrays and reports errors; every computation is libsgbake's, reached through
its C ABI (include/sgbake/sgbake.h) with ctypes (capi.py). The baked pixels go into a Blender
image, every tile of a UDIM image. Modules:
  capi.py        ctypes binding (no bpy): finds and loads libsgbake.so, calls sgbake_bake_map
  library.py     loads the library on first use (preferences path, $SGBAKE_LIBRARY, ...)
  scene.py       the settings as an sgbake scene (JSON), keys only where they apply
  gather.py      the evaluated mesh and the layers' images as numpy arrays; pixels back
                 (UDIM tiles through temporary files, packed)
  properties.py  scene.sgbake: the map, its size and padding, the layers
  operators.py   Bake, Layers from Material, and the layer list's add/remove/move
  ui.py          the panel in Properties > Render
See plugin/README.md.
"""

bl_info = {
    "name": "sgbake",
    "author": "sgbake",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Render > sgbake",
    "description": "Bake normal, height and surface-gradient maps with libsgbake",
    "category": "Render",
}

# bl_info comes first by Blender's convention (its add-on list reads it without importing).
import bpy  # noqa: E402
from bpy.props import StringProperty  # noqa: E402

from . import library, operators, properties, ui  # noqa: E402


class SgbakePreferences(bpy.types.AddonPreferences):
    """Where libsgbake.so is; empty: $SGBAKE_LIBRARY, the add-on's folder, the system path."""
    bl_idname = __package__

    library_path: StringProperty(
        name="Library", subtype="FILE_PATH",
        description="Path of libsgbake.so (empty: $SGBAKE_LIBRARY, then libsgbake.so in the "
                    "add-on's folder, then the system library path)")

    def draw(self, context):
        self.layout.prop(self, "library_path")
        loaded, line = library.describe(context)
        self.layout.label(text=line, icon="CHECKMARK" if loaded else "ERROR")


def register():
    bpy.utils.register_class(SgbakePreferences)
    properties.register()
    for cls in operators.CLASSES + ui.CLASSES:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(operators.CLASSES + ui.CLASSES):
        bpy.utils.unregister_class(cls)
    properties.unregister()
    bpy.utils.unregister_class(SgbakePreferences)
