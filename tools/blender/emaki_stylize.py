# The emaki add-on's "Stylize current frame" action (registered by emaki_passes.py, which must
# sit beside this file, as it does in the add-on's package emaki_blender/): renders the current frame's guide passes through the exporter, then
# stylizes the frame in this Blender process through emaki's Python module (emaki.synthesize),
# as a `base` layer would (guides normal 1 + diffuse 1, the frame's coverage as the mask), and
# shows the result as an image ("emaki frame NNNN") in an Image Editor.
#
# The module: build/release/python/emaki*.so, built for Debian's Python 3.11, which Debian's
# Blender runs. Blender ignores PYTHONPATH unless started with --python-use-system-env, so the
# panel has a "Module folder" setting (also read from the environment variable EMAKI_PYTHONPATH);
# without one, the module is looked for in the install of the emaki executable the add-on's
# preference names (else `emaki` on PATH): PREFIX/lib/python3/dist-packages.

import os
import shutil
import sys

import bpy

# Guides of emaki's `base` layer kind (docs/shot_file.md) and their weights.
GUIDES = (("normal", 1.0), ("diffuse", 1.0))


class StylizeError(Exception):
    pass


def installed_module_folder():
    """PREFIX/lib/python3/dist-packages of the emaki executable the add-on uses (its preference,
    else PATH; docs/install.md), or ""."""
    addon = sys.modules.get("emaki_blender")
    exe = addon.emaki_executable() if addon else shutil.which("emaki")
    if not exe:
        return ""
    prefix = os.path.dirname(os.path.dirname(os.path.realpath(exe)))
    return os.path.join(prefix, "lib", "python3", "dist-packages")


def import_emaki(folder):
    """The emaki module, from `folder` (or EMAKI_PYTHONPATH, or the install of the emaki
    executable) when it is not importable as is."""
    for extra in (folder, os.environ.get("EMAKI_PYTHONPATH", ""), installed_module_folder()):
        extra = bpy.path.abspath(extra) if extra else ""
        if extra and extra not in sys.path:
            sys.path.insert(0, extra)
    try:
        import emaki
    except ImportError as e:
        raise StylizeError("cannot import emaki's Python module (%s): set the module folder "
                           "(build/release/python, or PREFIX/lib/python3/dist-packages)" % e)
    return emaki


def read_pass(emaki, path, name):
    """A pass of a multilayer EXR by emaki's pass name: emaki's channel names, or the
    exporter's NAME.V for one-channel passes."""
    have = emaki.image_channels(path)
    wanted = emaki.pass_channels[name]
    if not all(c in have for c in wanted):
        wanted = [c for c in have if c.startswith(name + ".")]
    if not wanted:
        raise StylizeError("%s: no '%s' pass (channels: %s)" % (path, name, ", ".join(have[:12])))
    return emaki.read_image(path, channels=wanted)


def stylize(emaki, painting, painting_passes, frame_passes):
    """B' for one frame: float32 HxWx(C+1), the painting's channels and the coverage as alpha."""
    import numpy as np
    style = emaki.read_image(painting)
    guides = [(read_pass(emaki, painting_passes, name), read_pass(emaki, frame_passes, name),
               weight) for name, weight in GUIDES]
    coverage = read_pass(emaki, frame_passes, "alpha")
    return emaki.synthesize(style, guides, coverage, dtype=np.float32)


def show_image(context, name, pixels):
    """`pixels` (HxWx1-4, sRGB-encoded like the painting, top row first) as a byte image."""
    import numpy as np
    h, w, c = pixels.shape
    rgba = np.ones((h, w, 4), np.float32)
    rgba[:, :, :3] = pixels[:, :, :3] if c >= 3 else pixels[:, :, :1]
    if c in (2, 4):
        rgba[:, :, 3] = pixels[:, :, c - 1]
    image = bpy.data.images.get(name)
    if image is not None and (image.size[0] != w or image.size[1] != h):
        bpy.data.images.remove(image)
        image = None
    if image is None:
        image = bpy.data.images.new(name, w, h, alpha=True)
    image.pixels.foreach_set(np.ascontiguousarray(rgba[::-1]).ravel())  # Blender: bottom row first
    image.update()
    for area in (context.screen.areas if context.screen else []):
        if area.type == "IMAGE_EDITOR":
            area.spaces.active.image = image
            break
    return image


class EMAKI_OT_stylize_frame(bpy.types.Operator):
    bl_idname = "emaki.stylize_frame"
    bl_label = "Stylize current frame"
    bl_description = ("Render the current frame's emaki passes, stylize it with the painting "
                      "in this Blender (emaki's Python module) and show it as an image")

    def execute(self, context):
        import emaki_passes
        scene = context.scene
        frame = scene.frame_current
        out = bpy.path.abspath(scene.emaki_out)
        try:
            emaki = import_emaki(scene.emaki_python)
            painting = bpy.path.abspath(scene.emaki_painting)
            painting_passes = bpy.path.abspath(scene.emaki_painting_passes)
            for label, path in (("Painting", painting), ("Painting passes", painting_passes)):
                if not os.path.isfile(path):
                    raise StylizeError("%s: no file '%s'" % (label, path))
            failure = emaki_passes.export_frames(context, out, frame, frame)
            if failure:
                raise StylizeError(failure)
            frame_passes = os.path.join(out, "frame_%04d.exr" % frame)
            result = stylize(emaki, painting, painting_passes, frame_passes)
        except (StylizeError, emaki_passes.ExportError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        except Exception as e:  # emaki.Error and the like: one line naming the file or argument
            self.report({"ERROR"}, "emaki: %s" % e)
            return {"CANCELLED"}
        image = show_image(context, "emaki frame %04d" % frame, result)
        self.report({"INFO"}, "emaki: stylized frame %d into image '%s'" % (frame, image.name))
        return {"FINISHED"}


def draw(layout, scene):
    col = layout.column()
    col.separator()
    col.label(text="Stylize (emaki's Python module)")
    col.prop(scene, "emaki_painting")
    col.prop(scene, "emaki_painting_passes")
    col.prop(scene, "emaki_python")
    col.operator(EMAKI_OT_stylize_frame.bl_idname)


PROPS = {
    "emaki_painting": lambda: bpy.props.StringProperty(
        name="Painting", subtype="FILE_PATH",
        description="The painted exemplar (e.g. the painted template)"),
    "emaki_painting_passes": lambda: bpy.props.StringProperty(
        name="Painting passes", subtype="FILE_PATH",
        description="The painting's passes: reference.exr from the exporter's --reference, or a "
                    "key frame's passes"),
    "emaki_python": lambda: bpy.props.StringProperty(
        name="Module folder", subtype="DIR_PATH",
        description="Folder holding emaki's Python module (build/release/python), when Blender "
                    "cannot import it as is"),
}


def register():
    for name, make in PROPS.items():
        setattr(bpy.types.Scene, name, make())
    bpy.utils.register_class(EMAKI_OT_stylize_frame)


def unregister():
    bpy.utils.unregister_class(EMAKI_OT_stylize_frame)
    for name in PROPS:
        delattr(bpy.types.Scene, name)
