# A small animated test scene, made from nothing: a ground plane, a cube, a smooth sphere and a
# torus with their own colours, a cone without a material, the cube sliding and turning, the
# camera moving over frames 1-4, a sun. Saved as a .blend for the exporter (and a plain render) to open.
#   blender -b --factory-startup -P make_scene.py -- OUT.blend
import math
import sys

import bpy

out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.frame_start, scene.frame_end = 1, 4


def material(name, rgb):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*rgb, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.8
    return m


bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, 0))
ground = bpy.context.active_object
ground.name = "ground"
ground.data.materials.append(material("ground", (0.8, 0.8, 0.8)))

bpy.ops.mesh.primitive_cube_add(size=1.2, location=(-1.2, 0, 0.6))
cube = bpy.context.active_object
cube.name = "cube"
cube.data.materials.append(material("red", (0.8, 0.2, 0.15)))
cube.keyframe_insert("location", frame=1)
cube.keyframe_insert("rotation_euler", frame=1)
cube.location.x += 0.4
cube.rotation_euler.z = math.radians(25)
cube.keyframe_insert("location", frame=4)
cube.keyframe_insert("rotation_euler", frame=4)

bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.7, location=(0.6, 0.4, 0.7))
sphere = bpy.context.active_object
sphere.name = "sphere"
bpy.ops.object.shade_smooth()
sphere.data.materials.append(material("blue", (0.2, 0.35, 0.8)))

bpy.ops.mesh.primitive_torus_add(major_radius=0.5, minor_radius=0.18, location=(0.3, -1.3, 0.18))
torus = bpy.context.active_object
torus.name = "torus"
bpy.ops.object.shade_smooth()
torus.data.materials.append(material("yellow", (0.85, 0.7, 0.2)))

# No material at all: the exporter gives it a default one carrying its AOVs.
bpy.ops.mesh.primitive_cone_add(radius1=0.35, depth=0.8, location=(1.9, -0.6, 0.4))
bpy.context.active_object.name = "cone"

cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(cam)
scene.camera = cam
cam.data.lens = 35
for frame, x in ((1, 6.0), (4, 5.2)):
    cam.location = (x, -5.5 + 0.3 * frame, 3.2)
    direction = cam.location.copy() * -1.0
    direction.z += 0.5
    cam.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    cam.keyframe_insert("location", frame=frame)
    cam.keyframe_insert("rotation_euler", frame=frame)

sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
sun.rotation_euler = (math.radians(40), math.radians(15), math.radians(-30))
scene.collection.objects.link(sun)
scene.world = bpy.data.worlds.new("world")
scene.render.resolution_x, scene.render.resolution_y = 160, 90
scene.render.resolution_percentage = 100
bpy.ops.wm.save_as_mainfile(filepath=out)
