# A plain Blender render, as a studio would make one without emaki's exporter: Cycles, one
# multilayer EXR per frame with Blender's own passes (Normal, Position, Depth, Vector, Diffuse
# Direct / Color, Object / Material Index) and a transparent film.
#   blender -b [scene.blend] -P plain_render.py -- --out DIR --frames A-B [--size WxH]
#           [--samples N] [--gltf FILE --look-from=X,Y,Z --look-at=X,Y,Z --fov DEG]
import argparse
import os
import sys

import bpy

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools",
                                "blender"))
import emaki_passes  # noqa: E402  (its glTF import and look-at camera)

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
p = argparse.ArgumentParser()
p.add_argument("--out", required=True)
p.add_argument("--frames", required=True)
p.add_argument("--size")
p.add_argument("--samples", type=int, default=16)
p.add_argument("--gltf")
p.add_argument("--look-from")
p.add_argument("--look-at")
p.add_argument("--fov", type=float, default=40.0)
a = p.parse_args(argv)

scene = emaki_passes.import_gltf(a.gltf) if a.gltf else bpy.context.scene
if a.look_from:
    emaki_passes.add_look_at_camera(scene, emaki_passes.parse_triple(a.look_from, "--look-from"),
                                    emaki_passes.parse_triple(a.look_at, "--look-at"), a.fov)
if scene.world is None:
    scene.world = bpy.data.worlds.new("world")
if not any(o.type == "LIGHT" for o in scene.objects):
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.rotation_euler = (0.8, 0.2, -0.6)
    scene.collection.objects.link(sun)
if a.size:
    scene.render.resolution_x, scene.render.resolution_y = (int(x) for x in a.size.split("x"))
    scene.render.resolution_percentage = 100
scene.render.engine = "CYCLES"
scene.cycles.samples = a.samples
scene.cycles.use_denoising = False
scene.cycles.device = "CPU"
scene.render.film_transparent = True
scene.render.use_motion_blur = False
vl = scene.view_layers[0]
for attr in ("use_pass_z", "use_pass_normal", "use_pass_position", "use_pass_vector",
             "use_pass_diffuse_direct", "use_pass_diffuse_color", "use_pass_object_index",
             "use_pass_material_index"):
    setattr(vl, attr, True)
vl.cycles.denoising_store_passes = False
scene.render.image_settings.file_format = "OPEN_EXR_MULTILAYER"
scene.render.image_settings.color_depth = "32"
first, last = (int(x) for x in a.frames.split("-"))
for f in range(first, last + 1):
    scene.frame_set(f)
    scene.render.filepath = os.path.join(os.path.abspath(a.out), "frame_%04d.exr" % f)
    bpy.ops.render.render(write_still=True)
