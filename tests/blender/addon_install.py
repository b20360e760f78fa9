# Run by addon_install.sh inside Blender: installs the add-on zip with Blender's own installer,
# enables it, and checks what it registers and where it finds emaki.
#   blender -b --factory-startup -P addon_install.py -- ZIP VERSION EXPECTED_EMAKI
import os
import sys

import bpy

zip_path, version, expected_emaki = sys.argv[sys.argv.index("--") + 1:]

bpy.ops.preferences.addon_install(filepath=zip_path)
bpy.ops.preferences.addon_enable(module="emaki_blender")

import emaki_blender  # noqa: E402  (installed just now)

assert emaki_blender.bl_info["version"] == tuple(int(v) for v in version.split(".")), \
    emaki_blender.bl_info
assert "emaki_blender" in bpy.context.preferences.addons
for prop in ("emaki_out", "emaki_samples", "emaki_painting", "emaki_python"):
    assert hasattr(bpy.types.Scene, prop), prop
assert hasattr(bpy.types, "EMAKI_PT_panel")
assert hasattr(bpy.ops.emaki, "render_passes") and hasattr(bpy.ops.emaki, "stylize_frame")

# The executable: `emaki` on PATH by default; the preference when set (None when it is not a
# program); the Python module looked for in that install's PREFIX/lib/python3/dist-packages.
assert emaki_blender.emaki_executable() == expected_emaki, emaki_blender.emaki_executable()
import emaki_stylize  # noqa: E402
prefix = os.path.dirname(os.path.dirname(os.path.realpath(expected_emaki)))
assert emaki_stylize.installed_module_folder() == os.path.join(prefix, "lib", "python3",
                                                               "dist-packages")
prefs = bpy.context.preferences.addons["emaki_blender"].preferences
prefs.executable = "/nonexistent/emaki"
assert emaki_blender.emaki_executable() is None
prefs.executable = expected_emaki
assert emaki_blender.emaki_executable() == expected_emaki

bpy.ops.preferences.addon_disable(module="emaki_blender")
assert not hasattr(bpy.types.Scene, "emaki_out")
print("emaki add-on: installed, enabled, disabled")
