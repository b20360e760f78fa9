# emaki pass exporter for Blender 3.4 and newer (Cycles).
#
# Renders one multilayer EXR per frame holding emaki's guide passes (docs/passes.md) under
# emaki's channel names, in emaki's conventions (camera-space normals, glTF-style +Y-up world
# positions, pixels-down motion to the previous frame, values not premultiplied by alpha):
#
#   blender -b scene.blend -P tools/blender/emaki_passes.py -- --out DIR --frames A-B
#   blender -b -P tools/blender/emaki_passes.py -- --reference --out DIR      # reference sphere
#   blender -b -P tools/blender/emaki_passes.py -- --gltf scene.glb --out DIR --frames 0-4
#
# `-- --help` lists every option. As part of the add-on (the package emaki_blender/, whose
# __init__.py holds bl_info; the build zips it, docs/blender.md), it adds an "emaki" panel to the
# Output properties: render the passes of the frame range, and stylize the current frame in
# Blender through emaki's Python module (emaki_stylize.py).
#
# How each pass is made (docs/blender.md has the conventions):
#   normal, position, position_norm, rest_position, depth: a shader AOV written by a node group
#     that the exporter adds to every material (camera-space normal via Vector Transform;
#     position swizzled from Blender's Z-up to +Y-up; rest position from the undeformed
#     "Generated" coordinates scaled back to object space through per-object properties).
#   diffuse: Cycles' Diffuse Direct pass under one white sun of strength pi with the world dark
#     (light without colour); shadow: 1 - Diffuse Direct / (N.L), faded as N.L goes to 0.
#   albedo: Diffuse Color. object_id / material_id: Object / Material Index, set by the exporter
#     (1 for the ground, 2.. for the other objects / materials, sorted by name).
#   outline: a line pass made in the compositor: Sobel edges of the object and material ids
#     (ground against background excluded), of log depth (depth jumps) and of the normal
#     (creases).
#   motion: Cycles' Vector pass (pixels from here to the previous position, x right, y up)
#     with y turned down, as emaki's.
#   alpha: the film's alpha with a transparent background.
# Beside the frames, colour.toml: the scene's colour management (the OpenColorIO config Blender
# runs with, its display and view) as shot-file keys (docs/blender.md).
# Single-channel passes come out as NAME.V (the File Output node's name for a value socket);
# emaki's `emaki` channel preset reads NAME.V as well as emaki's own NAME.Y / .Z / .A.

import json
import math
import os
import sys

import bpy
import mathutils

GROUP = "emaki_passes"
AOVS = [  # name, type
    ("emaki_normal", "COLOR"),
    ("emaki_position", "COLOR"),
    ("emaki_position_norm", "COLOR"),
    ("emaki_rest_position", "COLOR"),
    ("emaki_depth", "VALUE"),
    ("emaki_ndotl", "VALUE"),
]


class ExportError(Exception):
    pass


# ---- coordinates -----------------------------------------------------------------------------


def to_yup(v):
    """Blender world (Z up) -> emaki / glTF world (+Y up)."""
    return mathutils.Vector((v[0], v[2], -v[1]))


def from_yup(v):
    return mathutils.Vector((v[0], -v[2], v[1]))


def cube_around(lo, hi):
    """emaki's normalisation cube: centred on the box, side = its largest extent."""
    size = max(hi[i] - lo[i] for i in range(3))
    size = max(size, 1e-6)
    c = [(lo[i] + hi[i]) * 0.5 for i in range(3)]
    return mathutils.Vector([c[i] - 0.5 * size for i in range(3)]), size


def ground_objects(scene, ground_name):
    out = set()
    for ob in scene.objects:
        if ob.type != "MESH":
            continue
        if ground_name and ob.name == ground_name:
            out.add(ob)
        elif not ground_name and (ob.name.lower().startswith("ground") or ob.get("emaki_ground")):
            out.add(ob)
    return out


def render_meshes(scene):
    return sorted((ob for ob in scene.objects if ob.type == "MESH" and not ob.hide_render),
                  key=lambda o: o.name)


def shot_box(scene, frames, grounds):
    """Union of the (non-ground) objects' world bounds over the frames, +Y up."""
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for f in frames:
        scene.frame_set(f)
        dg = bpy.context.evaluated_depsgraph_get()
        for ob in render_meshes(scene):
            if ob in grounds:
                continue
            ev = ob.evaluated_get(dg)
            mesh = ev.to_mesh()
            for v in mesh.vertices:
                p = to_yup(ev.matrix_world @ v.co)
                for i in range(3):
                    lo[i] = min(lo[i], p[i])
                    hi[i] = max(hi[i], p[i])
            ev.to_mesh_clear()
    if lo[0] == math.inf:
        return mathutils.Vector((-1, -1, -1)), 2.0
    return cube_around(lo, hi)


def rest_box(scene, grounds):
    """The cube around every object's rest (undeformed) mesh in its own space, +Y up."""
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for ob in render_meshes(scene):
        if ob in grounds:
            continue
        for v in ob.data.vertices:
            p = to_yup(v.co)
            for i in range(3):
                lo[i] = min(lo[i], p[i])
                hi[i] = max(hi[i], p[i])
    if lo[0] == math.inf:
        return mathutils.Vector((-1, -1, -1)), 2.0
    return cube_around(lo, hi)


# ---- the shader side: one node group, added to every material --------------------------------


def build_group(box_lo, box_size, rest_lo, rest_size, light_world):
    """The AOVs as a node group; its constants are the shot's boxes and the light direction."""
    if GROUP in bpy.data.node_groups:
        bpy.data.node_groups.remove(bpy.data.node_groups[GROUP])
    g = bpy.data.node_groups.new(GROUP, "ShaderNodeTree")
    n, link = g.nodes, g.links.new
    out = n.new("NodeGroupOutput")
    for name, kind in AOVS:
        sock = "NodeSocketColor" if kind == "COLOR" else "NodeSocketFloat"
        g.outputs.new(sock, name)

    geo = n.new("ShaderNodeNewGeometry")

    def vmath(op, a, b=None):
        m = n.new("ShaderNodeVectorMath")
        m.operation = op
        link(a, m.inputs[0])
        if b is not None:
            if isinstance(b, (tuple, list, mathutils.Vector)):
                m.inputs[1].default_value = b
            else:
                link(b, m.inputs[1])
        return m.outputs["Value" if op in ("DOT_PRODUCT", "LENGTH") else "Vector"]

    def swizzle_yup(sock):
        s = n.new("ShaderNodeSeparateXYZ")
        link(sock, s.inputs[0])
        neg = n.new("ShaderNodeMath")
        neg.operation = "MULTIPLY"
        link(s.outputs["Y"], neg.inputs[0])
        neg.inputs[1].default_value = -1.0
        c = n.new("ShaderNodeCombineXYZ")
        link(s.outputs["X"], c.inputs["X"])
        link(s.outputs["Z"], c.inputs["Y"])
        link(neg.outputs[0], c.inputs["Z"])
        return c.outputs[0]

    # normal: camera space. Cycles' camera space is x right, y up, z *away* from the viewer
    # (measured); emaki's z points towards the viewer.
    nt = n.new("ShaderNodeVectorTransform")
    nt.vector_type, nt.convert_from, nt.convert_to = "NORMAL", "WORLD", "CAMERA"
    link(geo.outputs["Normal"], nt.inputs[0])
    link(vmath("MULTIPLY", vmath("NORMALIZE", nt.outputs[0]), (1.0, 1.0, -1.0)),
         out.inputs["emaki_normal"])

    pos = swizzle_yup(geo.outputs["Position"])
    link(pos, out.inputs["emaki_position"])
    inv = 1.0 / box_size
    pn = vmath("MULTIPLY", vmath("SUBTRACT", pos, tuple(box_lo)), (inv, inv, inv))
    link(pn, out.inputs["emaki_position_norm"])

    # rest position: Generated coordinates (undeformed mesh over its texture space) back to
    # object space through two per-object properties the exporter sets, then into the rest cube.
    tc = n.new("ShaderNodeTexCoord")
    sc = n.new("ShaderNodeAttribute")
    sc.attribute_type, sc.attribute_name = "OBJECT", "emaki_texspace_scale"
    of = n.new("ShaderNodeAttribute")
    of.attribute_type, of.attribute_name = "OBJECT", "emaki_texspace_offset"
    obj = vmath("ADD", vmath("MULTIPLY", tc.outputs["Generated"], sc.outputs["Vector"]),
                of.outputs["Vector"])
    rinv = 1.0 / rest_size
    rn = vmath("MULTIPLY", vmath("SUBTRACT", swizzle_yup(obj), tuple(rest_lo)), (rinv, rinv, rinv))
    # The ground (no properties: scale 0) takes its position_norm, as in emaki's renderer.
    is_ground = n.new("ShaderNodeAttribute")
    is_ground.attribute_type, is_ground.attribute_name = "OBJECT", "emaki_is_ground"
    mix = n.new("ShaderNodeMix")
    mix.data_type = "VECTOR"
    link(is_ground.outputs["Fac"], mix.inputs["Factor"])
    link(rn, mix.inputs[4])
    link(pn, mix.inputs[5])
    link(mix.outputs[1], out.inputs["emaki_rest_position"])

    # depth: distance from the camera plane along the viewing axis.
    pt = n.new("ShaderNodeVectorTransform")
    pt.vector_type, pt.convert_from, pt.convert_to = "POINT", "WORLD", "CAMERA"
    link(geo.outputs["Position"], pt.inputs[0])
    sz = n.new("ShaderNodeSeparateXYZ")
    link(pt.outputs[0], sz.inputs[0])
    link(sz.outputs["Z"], out.inputs["emaki_depth"])  # Cycles' camera z grows into the scene

    # N.L with the key light (world space), for the shadow pass.
    link(vmath("DOT_PRODUCT", geo.outputs["Normal"], tuple(light_world)), out.inputs["emaki_ndotl"])
    return g


def add_group_to_materials(scene):
    """Every rendered mesh gets a material carrying the AOV outputs (its colour kept)."""
    fallback = None
    materials = set()
    for ob in render_meshes(scene):
        if not ob.material_slots or all(s.material is None for s in ob.material_slots):
            if fallback is None:
                fallback = bpy.data.materials.new("emaki_default")
                fallback.use_nodes = True
            if not ob.material_slots:
                ob.data.materials.append(fallback)
            else:
                for s in ob.material_slots:
                    s.material = fallback
        for s in ob.material_slots:
            if s.material is not None:
                materials.add(s.material)
    for mat in materials:
        if not mat.use_nodes:
            colour = tuple(mat.diffuse_color)
            mat.use_nodes = True
            bsdf = mat.node_tree.nodes.get("Principled BSDF")
            if bsdf:
                bsdf.inputs["Base Color"].default_value = colour
        nt = mat.node_tree
        for node in [x for x in nt.nodes if x.get("emaki")]:
            nt.nodes.remove(node)
        grp = nt.nodes.new("ShaderNodeGroup")
        grp.node_tree = bpy.data.node_groups[GROUP]
        grp["emaki"] = True
        for name, _ in AOVS:
            aov = nt.nodes.new("ShaderNodeOutputAOV")
            aov["emaki"] = True
            aov.name = name
            sock = aov.inputs["Color" if name != "emaki_depth" and name != "emaki_ndotl" else "Value"]
            nt.links.new(grp.outputs[name], sock)
    return sorted(materials, key=lambda m: m.name)


# ---- the compositor side: unpremultiply, convert, write -------------------------------------


def build_compositor(scene, out_pattern_base, template_png=None):
    scene.use_nodes = True
    tree = scene.node_tree
    for node in list(tree.nodes):
        tree.nodes.remove(node)
    n, link = tree.nodes, tree.links.new
    rl = n.new("CompositorNodeRLayers")
    rl.scene = scene
    rl.layer = scene.view_layers[0].name
    comp = n.new("CompositorNodeComposite")
    link(rl.outputs["Image"], comp.inputs["Image"])

    alpha = rl.outputs["Alpha"]

    def mop(op, a, b=None, clamp=False):
        m = n.new("CompositorNodeMath")
        m.operation = op
        m.use_clamp = clamp
        if isinstance(a, (int, float)):
            m.inputs[0].default_value = a
        else:
            link(a, m.inputs[0])
        if b is not None:
            if isinstance(b, (int, float)):
                m.inputs[1].default_value = b
            else:
                link(b, m.inputs[1])
        return m.outputs[0]

    safe_alpha = mop("MAXIMUM", alpha, 1e-6)

    def unpremul_value(sock):
        return mop("DIVIDE", sock, safe_alpha)

    def separate(sock):
        s = n.new("CompositorNodeSeparateXYZ")
        link(sock, s.inputs[0])
        return s.outputs["X"], s.outputs["Y"], s.outputs["Z"]

    def combine(x, y, z):
        c = n.new("CompositorNodeCombineXYZ")
        for sock, name in ((x, "X"), (y, "Y"), (z, "Z")):
            if isinstance(sock, (int, float)):
                c.inputs[name].default_value = sock
            else:
                link(sock, c.inputs[name])
        return c.outputs[0]

    def unpremul_vec(sock):
        x, y, z = separate(sock)
        return combine(unpremul_value(x), unpremul_value(y), unpremul_value(z))

    def colour_channels(sock):
        s = n.new("CompositorNodeSeparateColor")
        link(sock, s.inputs[0])
        return s.outputs[0], s.outputs[1], s.outputs[2]

    def unpremul_rgb(sock):
        r, g, b = colour_channels(sock)
        c = n.new("CompositorNodeCombineColor")
        for i, v in enumerate((r, g, b)):
            link(unpremul_value(v), c.inputs[i])
        return c.outputs[0]

    def rgb_as_vec(sock):
        r, g, b = colour_channels(sock)
        return combine(unpremul_value(r), unpremul_value(g), unpremul_value(b))

    def unit_vec(sock):
        # An edge pixel averages differing normals; emaki's normal is unit length.
        r, g, b = colour_channels(sock)
        sq = mop("ADD", mop("ADD", mop("MULTIPLY", r, r), mop("MULTIPLY", g, g)),
                 mop("MULTIPLY", b, b))
        inv = mop("DIVIDE", 1.0, mop("MAXIMUM", mop("SQRT", sq), 1e-6))
        return combine(mop("MULTIPLY", r, inv), mop("MULTIPLY", g, inv), mop("MULTIPLY", b, inv))

    outs = {}
    outs["normal"] = unit_vec(rl.outputs["emaki_normal"])
    outs["position"] = rgb_as_vec(rl.outputs["emaki_position"])
    outs["position_norm"] = rgb_as_vec(rl.outputs["emaki_position_norm"])
    outs["rest_position"] = rgb_as_vec(rl.outputs["emaki_rest_position"])
    depth = unpremul_value(rl.outputs["emaki_depth"])
    outs["depth"] = depth
    # Diffuse Direct under a white sun of strength pi is max(0, N.L) x visibility.
    dr, dg, db = colour_channels(rl.outputs["DiffDir"])
    diffuse = mop("DIVIDE", mop("ADD", mop("ADD", dr, dg), db), 3.0)
    diffuse = mop("MINIMUM", unpremul_value(diffuse), 1.0)
    diffuse = mop("MAXIMUM", diffuse, 0.0)
    outs["diffuse"] = diffuse
    ndotl = unpremul_value(rl.outputs["emaki_ndotl"])
    vis = mop("DIVIDE", diffuse, mop("MAXIMUM", ndotl, 1e-3), clamp=True)
    # emaki: (1 - visibility) x clamp(10 N.L, 0, 1): cast shadow only.
    outs["shadow"] = mop("MULTIPLY", mop("SUBTRACT", 1.0, vis, clamp=True),
                          mop("MULTIPLY", ndotl, 10.0, clamp=True))
    outs["albedo"] = unpremul_rgb(rl.outputs["DiffCol"])
    # Index passes hold the id of the first sample; a pixel keeps it whole.
    obj_id = mop("ROUND", rl.outputs["IndexOB"])
    mat_id = mop("ROUND", rl.outputs["IndexMA"])
    outs["object_id"] = obj_id
    outs["material_id"] = mat_id

    # outline: Sobel edges of ids (objects only, so ground/background is no line), log depth
    # and the normal.
    def sobel(sock):
        f = n.new("CompositorNodeFilter")
        f.filter_type = "SOBEL"
        link(sock, f.inputs["Image"])
        return mop("MAXIMUM", mop("MAXIMUM", colour_channels(f.outputs[0])[0],
                                    colour_channels(f.outputs[0])[1]),
                    colour_channels(f.outputs[0])[2])

    objects_only = mop("MULTIPLY", obj_id, mop("GREATER_THAN", obj_id, 1.5))
    mats_only = mop("MULTIPLY", mat_id, mop("GREATER_THAN", obj_id, 1.5))
    id_edge = mop("GREATER_THAN", mop("MAXIMUM", sobel(objects_only), sobel(mats_only)), 0.5)
    log_depth = mop("MULTIPLY", mop("LOGARITHM", mop("MAXIMUM", depth, 1e-6), 2.718281828),
                     mop("GREATER_THAN", alpha, 0.5))
    # Depth jumps and creases inside the covered area only: the ground's far edge against the
    # background is no line (as in emaki's renderer); object silhouettes are id lines.
    interior = mop("LESS_THAN", sobel(mop("GREATER_THAN", alpha, 0.5)), 0.5)
    depth_edge = mop("MULTIPLY", mop("GREATER_THAN", sobel(log_depth), 0.25), interior)
    crease_edge = mop("MULTIPLY", mop("GREATER_THAN", sobel(outs["normal"]), 2.0), interior)
    outline = mop("MAXIMUM", mop("MAXIMUM", id_edge, depth_edge), crease_edge)
    outs["outline"] = mop("MULTIPLY", outline, mop("GREATER_THAN", alpha, 0.0))

    # motion: Blender's Vector.xy points from here to the previous position in pixels with
    # y up (measured against emaki's renderer on the Fox); emaki's y points down.
    vec = rl.outputs["Vector"]
    vs = n.new("CompositorNodeSeparateColor")
    link(vec, vs.inputs[0])
    mx = unpremul_value(vs.outputs[0])
    my = mop("MULTIPLY", unpremul_value(vs.outputs[1]), -1.0)
    outs["motion"] = combine(mx, my, 0.0)
    outs["alpha"] = alpha

    fo = n.new("CompositorNodeOutputFile")
    fo.format.file_format = "OPEN_EXR_MULTILAYER"
    fo.format.color_depth = "32"
    fo.format.exr_codec = "ZIP"
    fo.base_path = out_pattern_base
    fo.layer_slots.clear()
    for name, sock in outs.items():
        fo.layer_slots.new(name)
        link(sock, fo.inputs[name])

    if template_png:
        # The reference sphere's paint template, as emaki's: soft-lit grey sphere on a lighter
        # ground, the cast shadow and contour faintly marked, over a light background.
        lit = mop("ADD", 0.30, mop("MULTIPLY", mop("POWER", diffuse, 0.8), 0.5))
        sphere_v = mop("MULTIPLY", lit, mop("SUBTRACT", 1.0, mop("MULTIPLY", outs["shadow"], 0.15)))
        ground_v = mop("MULTIPLY", 0.72, mop("SUBTRACT", 1.0, mop("MULTIPLY", outs["shadow"], 0.22)))
        is_sphere = mop("GREATER_THAN", obj_id, 1.5)
        v = mop("ADD", mop("MULTIPLY", is_sphere, sphere_v),
                 mop("MULTIPLY", mop("SUBTRACT", 1.0, is_sphere), ground_v))
        v = mop("ADD", mop("MULTIPLY", alpha, v),
                 mop("MULTIPLY", mop("SUBTRACT", 1.0, alpha), 0.85))
        v = mop("MULTIPLY", v, mop("SUBTRACT", 1.0, mop("MULTIPLY", outs["outline"], 0.35)))
        # sRGB-encoded as emaki's (the File Output node writes the values as they are; v stays
        # above the curve's linear toe).
        v = mop("SUBTRACT", mop("MULTIPLY", mop("POWER", v, 1.0 / 2.4), 1.055), 0.055)
        t = n.new("CompositorNodeOutputFile")
        t.format.file_format = "PNG"
        t.format.color_mode = "RGB"
        t.base_path = os.path.dirname(template_png)
        t.file_slots.clear()
        t.file_slots.new(os.path.basename(template_png))
        link(v, t.inputs[0])
    return fo


# ---- the render setup ------------------------------------------------------------------------


def key_light(scene, light, light_world, softness):
    """One white sun of strength pi: the scene's first sun, or one made from `light` (camera
    relative unless light_world). Other lights and the world's light are switched off."""
    sun = None
    for ob in scene.objects:
        if ob.type == "LIGHT":
            if sun is None and ob.data.type == "SUN" and light is None and not ob.hide_render:
                sun = ob
            else:
                ob.hide_render = True
    if sun is None:
        data = bpy.data.lights.new("emaki_key", "SUN")
        sun = bpy.data.objects.new("emaki_key", data)
        scene.collection.objects.link(sun)
        d = mathutils.Vector(light or (-1.0, 1.0, 1.0)).normalized()
        if light_world:
            d = from_yup(d)
        else:
            cam = scene.camera.matrix_world.to_3x3().normalized()
            d = (cam @ d).normalized()
        sun.rotation_euler = d.to_track_quat("Z", "Y").to_euler()
    # Cycles' sun of strength S lights a white diffuse surface facing it to S / pi: strength pi
    # makes Diffuse Direct = max(0, N.L) x visibility.
    sun.data.energy = math.pi
    sun.data.color = (1.0, 1.0, 1.0)
    sun.data.angle = math.radians(softness)
    bpy.context.view_layer.update()
    direction = (sun.matrix_world.to_3x3() @ mathutils.Vector((0, 0, 1))).normalized()
    world = bpy.data.worlds.new("emaki_dark")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    return direction


def set_ids(scene, grounds, materials):
    ground_mats = set()
    for ob in grounds:
        for s in ob.material_slots:
            if s.material:
                ground_mats.add(s.material)
    i = 2
    for ob in render_meshes(scene):
        if ob in grounds:
            ob.pass_index = 1
            ob["emaki_is_ground"] = 1.0
        else:
            ob.pass_index = i
            ob["emaki_is_ground"] = 0.0
            i += 1
        # Generated = (rest coordinate - (loc - size)) / (2 size): back to object space.
        me = ob.data
        loc, size = mathutils.Vector(me.texspace_location), mathutils.Vector(me.texspace_size)
        ob["emaki_texspace_scale"] = list(2.0 * size)
        ob["emaki_texspace_offset"] = list(loc - size)
    j = 2
    for m in materials:
        if m in ground_mats:
            m.pass_index = 1
        else:
            m.pass_index = j
            j += 1


def setup(scene, out_base, frames, size, samples, light, light_world, softness, ground_name,
          template_png=None):
    if scene.camera is None:
        raise ExportError("the scene has no camera (set one with --camera or scene.camera)")
    if size:
        scene.render.resolution_x, scene.render.resolution_y = size
        scene.render.resolution_percentage = 100
    r = scene.render
    r.engine = "CYCLES"
    r.film_transparent = True
    r.use_motion_blur = False
    r.use_freestyle = False
    r.filter_size = 1.0
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.device = "CPU"
    vl = scene.view_layers[0]
    for ly in scene.view_layers[1:]:
        ly.use = False
    vl.use_pass_combined = True
    vl.use_pass_z = True
    vl.use_pass_vector = True
    vl.use_pass_diffuse_direct = True
    vl.use_pass_diffuse_color = True
    vl.use_pass_object_index = True
    vl.use_pass_material_index = True
    vl.cycles.denoising_store_passes = False
    existing = {a.name for a in vl.aovs}
    for name, kind in AOVS:
        if name not in existing:
            a = vl.aovs.add()
            a.name = name
        next(a for a in vl.aovs if a.name == name).type = kind

    grounds = ground_objects(scene, ground_name)
    box_lo, box_size = shot_box(scene, frames, grounds)
    rest_lo, rest_size = rest_box(scene, grounds)
    scene.frame_set(frames[0])
    direction = key_light(scene, light, light_world, softness)
    build_group(box_lo, box_size, rest_lo, rest_size, direction)
    materials = add_group_to_materials(scene)
    set_ids(scene, grounds, materials)
    build_compositor(scene, out_base, template_png)
    return {"box": (list(box_lo), box_size), "rest_box": (list(rest_lo), rest_size),
            "light": list(to_yup(direction))}


def blender_ocio_config():
    """The OpenColorIO config this Blender runs with: $OCIO, else its own datafiles."""
    env = os.environ.get("OCIO")
    if env:
        return env
    for kind in ("LOCAL", "SYSTEM"):
        path = os.path.join(bpy.utils.resource_path(kind), "datafiles", "colormanagement",
                            "config.ocio")
        if os.path.isfile(path):
            return path
    return None


def toml_string(text):
    # A TOML basic string: JSON's escapes are TOML's (json.dumps writes no "\/").
    return json.dumps(text, ensure_ascii=False)


def write_colour_settings(scene, out_dir):
    """colour.toml: the scene's colour management as shot-file keys. The passes are written
    scene-linear (EXR ignores the view), which the shot's default source.passes_colorspace
    already says; the previews are to look as Blender shows the scene."""
    config = blender_ocio_config()
    lines = ["# The colour management of Blender's scene '%s', as emaki's shot keys: copy them into"
             % scene.name.replace("\n", " "),
             "# the shot file's tables of the same names (docs/shot_file.md#colour-management).",
             ""]
    if config:
        lines += ["[colour]", "config = %s" % toml_string(os.path.abspath(config)), ""]
    lines += ["[source]", 'passes_colorspace = "scene_linear"', "",
              "[outputs]",
              "display = %s" % toml_string(scene.display_settings.display_device),
              "view = %s" % toml_string(scene.view_settings.view_transform)]
    if scene.view_settings.look not in ("", "None"):
        lines.append("# Blender's look '%s' has no shot key: emaki applies no look." %
                     scene.view_settings.look.replace("\n", " "))
    path = os.path.join(out_dir, "colour.toml")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    print("emaki: wrote %s" % path, flush=True)


def render_frames(scene, out_dir, frames):
    written = []
    for f in frames:
        scene.frame_set(f)
        bpy.ops.render.render(write_still=False)
        path = os.path.join(out_dir, "frame_%04d.exr" % f)
        if not os.path.isfile(path):
            raise ExportError("Blender did not write '%s'" % path)
        written.append(path)
        print("emaki: wrote %s" % path, flush=True)
    return written


# ---- the reference sphere --------------------------------------------------------------------


def build_reference(size, sphere, elevation, fov, ground=True):
    """emaki's reference scene (src/exemplar/reference_sphere.cpp) in a fresh Blender scene:
    a unit sphere resting on the ground at the origin, the camera looking at its centre with a
    lens shift that puts the sphere's circle at `sphere` (cx, cy, r pixels; y down)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    w, h = size
    cx, cy, r = sphere if sphere else (0.5 * w, 0.5 * h, 0.3 * h)
    tan_half = math.tan(0.5 * math.radians(fov))
    focal = 0.5 * h / tan_half
    alpha = math.atan(r / focal)
    if not (0 < alpha <= math.radians(80)):
        raise ExportError("--sphere: radius %g px does not fit a %g degree field of view" % (r, fov))
    distance = 1.0 / math.sin(alpha)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64, radius=1.0,
                                         location=from_yup((0, 1, 0)))
    sph = bpy.context.active_object
    sph.name = "sphere"
    bpy.ops.object.shade_smooth()
    mat = bpy.data.materials.new("sphere")
    mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1)
    sph.data.materials.append(mat)
    if ground:
        bpy.ops.mesh.primitive_plane_add(size=2e4, location=(0, 0, 0))
        g = bpy.context.active_object
        g.name = "ground"
        gm = bpy.data.materials.new("ground")
        gm.use_nodes = True
        gm.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.8, 0.8, 0.8, 1)
        g.data.materials.append(gm)
    for m in bpy.data.materials:
        bsdf = m.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Specular"].default_value = 0.0
        bsdf.inputs["Roughness"].default_value = 1.0
    cam_data = bpy.data.cameras.new("camera")
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    el = math.radians(elevation)
    target = mathutils.Vector((0, 1, 0))
    pos = target + distance * mathutils.Vector((0, math.sin(el), math.cos(el)))
    cam.location = from_yup(pos)
    cam.rotation_euler = (from_yup(target) - from_yup(pos)).to_track_quat("-Z", "Y").to_euler()
    cam_data.sensor_fit = "VERTICAL"
    cam_data.angle_y = math.radians(fov)
    cam_data.clip_start = 0.01
    cam_data.clip_end = 1e5
    # The optical axis (the sphere's centre) must land on pixel (cx, cy). Blender's shift moves
    # the view window, in units of the sensor-fit side (the height here), so the axis moves the
    # other way.
    cam_data.shift_x = -(cx - 0.5 * w) / h
    cam_data.shift_y = (cy - 0.5 * h) / h
    scene.camera = cam
    scene.frame_start = scene.frame_end = 0
    return scene


def add_look_at_camera(scene, position, target, fov):
    """A camera as emaki's look_at: +Y-up world coordinates, vertical field of view."""
    data = bpy.data.cameras.new("emaki_camera")
    cam = bpy.data.objects.new("emaki_camera", data)
    scene.collection.objects.link(cam)
    cam.location = from_yup(position)
    cam.rotation_euler = (from_yup(target) - from_yup(position)).to_track_quat("-Z", "Y").to_euler()
    data.sensor_fit = "VERTICAL"
    data.angle_y = math.radians(fov)
    data.clip_start = 0.01
    data.clip_end = 1e6
    scene.camera = cam


# ---- command line ----------------------------------------------------------------------------


def parse_args(argv):
    import argparse

    class Parser(argparse.ArgumentParser):
        def error(self, message):  # one line, as every other error
            raise ExportError(message)

    p = Parser(
        prog="blender -b [scene.blend] -P emaki_passes.py --",
        description="Render emaki's guide passes as multilayer EXRs (DIR/frame_NNNN.exr), or "
                    "with --reference the reference sphere (DIR/reference.exr + template.png).")
    p.add_argument("--out", required=True, help="output folder (created)")
    p.add_argument("--frames", help="A-B, inclusive (default: the scene's frame range)")
    p.add_argument("--size", help="WxH in pixels (default: the scene's resolution)")
    p.add_argument("--samples", type=int, default=16, help="Cycles samples per pixel (16)")
    p.add_argument("--light", help="X,Y,Z towards the key light, camera-relative (x right, y up, "
                   "z to the viewer) unless --light-world (+Y up); default: the scene's sun, "
                   "else -1,1,1")
    p.add_argument("--light-world", action="store_true")
    p.add_argument("--softness", type=float, default=2.0, help="sun angle, degrees (2)")
    p.add_argument("--ground", help="name of the ground object (default: names starting "
                   "with 'ground', or objects with the property emaki_ground)")
    p.add_argument("--camera", help="name of the camera object to render from")
    p.add_argument("--gltf", help="import this glTF (.glb/.gltf) into an empty scene first")
    p.add_argument("--look-from", help="X,Y,Z: add a camera here (+Y-up world, as emaki's "
                   "--camera) looking at --look-at, with --fov (40)")
    p.add_argument("--look-at", help="X,Y,Z: the point --look-from looks at")
    p.add_argument("--reference", action="store_true",
                   help="render the reference sphere instead of the open scene")
    p.add_argument("--sphere", help="reference: CX,CY,R pixels (default: centred, 30%% of h)")
    # emaki's one default for the reference camera (exemplar::kDefaultReferenceElevationDeg;
    # python/tests/test_defaults.py checks that they agree).
    p.add_argument("--elevation", type=float, default=10.0, help="reference: degrees (10)")
    p.add_argument("--fov", type=float, help="vertical field of view, degrees (reference: 30, "
                   "--look-from: 40)")
    p.add_argument("--no-ground", action="store_true", help="reference: no ground plane")
    return p.parse_args(argv)


def parse_triple(text, option, count=3):
    try:
        v = [float(x) for x in text.split(",")]
    except ValueError:
        v = []
    if len(v) != count:
        raise ExportError("%s: expected %d comma-separated numbers, got '%s'" % (option, count, text))
    return v


def import_gltf(path):
    if not os.path.isfile(path):
        raise ExportError("--gltf: no such file '%s'" % path)
    # Debian's Blender 3.4 glTF importer still uses numpy.bool, removed in numpy 1.24.
    import numpy
    if not hasattr(numpy, "bool"):
        numpy.bool = bool
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=path)
    return bpy.context.scene


def make_folder(path):
    """Created once the arguments check out, so a refused run leaves nothing behind."""
    try:
        os.makedirs(path, exist_ok=True)
    except OSError as e:
        raise ExportError("--out: cannot create '%s': %s" % (path, e.strerror))
    if not os.access(path, os.W_OK):
        raise ExportError("--out: '%s' is not writable" % path)


def main(argv):
    args = parse_args(argv)
    out = os.path.abspath(args.out)
    size = None
    if args.size:
        try:
            w, h = (int(x) for x in args.size.lower().split("x"))
        except ValueError:
            raise ExportError("--size: expected WxH, got '%s'" % args.size)
        if not (1 <= w <= 16384 and 1 <= h <= 16384):
            raise ExportError("--size: width and height must be in [1, 16384]")
        size = (w, h)
    light = parse_triple(args.light, "--light") if args.light else None

    if args.reference:
        size = size or (1024, 768)
        sphere = parse_triple(args.sphere, "--sphere") if args.sphere else None
        scene = build_reference(size, sphere, args.elevation, args.fov or 30.0,
                                not args.no_ground)
        make_folder(out)
        info = setup(scene, os.path.join(out, "reference_"), [0], size, args.samples, light,
                     args.light_world, args.softness, "ground",
                     template_png=os.path.join(out, "template_"))
        scene.frame_set(0)
        bpy.ops.render.render(write_still=False)
        for stem, ext in (("reference", ".exr"), ("template", ".png")):
            src = os.path.join(out, "%s_0000%s" % (stem, ext))
            if not os.path.isfile(src):
                raise ExportError("Blender did not write '%s'" % src)
            os.replace(src, os.path.join(out, stem + ext))
        print("emaki: wrote %s/reference.exr and template.png (light %s)" % (out, info["light"]))
        return

    scene = import_gltf(args.gltf) if args.gltf else bpy.context.scene
    if args.camera:
        if args.camera not in bpy.data.objects:
            raise ExportError("--camera: no object '%s'" % args.camera)
        scene.camera = bpy.data.objects[args.camera]
    if args.look_from or args.look_at:
        if not (args.look_from and args.look_at):
            raise ExportError("--look-from and --look-at go together")
        add_look_at_camera(scene, parse_triple(args.look_from, "--look-from"),
                           parse_triple(args.look_at, "--look-at"), args.fov or 40.0)
    if args.frames:
        try:
            a, b = (int(x) for x in args.frames.split("-"))
        except ValueError:
            raise ExportError("--frames: expected A-B, got '%s'" % args.frames)
        if a < 0 or b < a:
            raise ExportError("--frames: need 0 <= A <= B, got '%s'" % args.frames)
    else:
        a, b = scene.frame_start, scene.frame_end
    frames = list(range(a, b + 1))
    make_folder(out)
    info = setup(scene, os.path.join(out, "frame_"), frames, size, args.samples, light,
                 args.light_world, args.softness, args.ground)
    render_frames(scene, out, frames)
    write_colour_settings(scene, out)
    print("emaki: box %s, rest box %s, light %s" % (info["box"], info["rest_box"], info["light"]))


# ---- add-on ----------------------------------------------------------------------------------


def export_frames(context, out, first, last):
    """Renders frames first..last of the open scene into `out` (frame_NNNN.exr) in a background
    Blender on a copy of the file: the export rewires materials, lights, world and compositor,
    and the open scene stays as it is. Returns None, or the error line."""
    import subprocess
    import tempfile
    scene = context.scene
    with tempfile.TemporaryDirectory() as tmp:
        copy = os.path.join(tmp, "scene.blend")
        bpy.ops.wm.save_as_mainfile(filepath=copy, copy=True)
        cmd = [bpy.app.binary_path, "-b", copy, "--scene", scene.name, "-P",
               os.path.abspath(__file__), "--", "--out", out, "--frames",
               "%d-%d" % (first, last), "--samples", str(scene.emaki_samples)]
        proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode == 0:
        return None
    print(proc.stdout[-4000:], proc.stderr[-4000:])
    lines = [l for l in proc.stderr.splitlines() if "emaki_passes: error" in l]
    return lines[-1] if lines else "the export failed (see the console)"


class EMAKI_OT_render_passes(bpy.types.Operator):
    bl_idname = "emaki.render_passes"
    bl_label = "Render emaki passes"
    bl_description = "Render the scene's frame range as emaki guide passes into the folder"

    def execute(self, context):
        scene = context.scene
        out = bpy.path.abspath(scene.emaki_out)
        failure = export_frames(context, out, scene.frame_start, scene.frame_end)
        if failure:
            self.report({"ERROR"}, failure)
            return {"CANCELLED"}
        self.report({"INFO"}, "emaki passes written to %s" % out)
        return {"FINISHED"}


def stylize_module():
    """emaki_stylize.py, beside this file: the in-process stylization (emaki's Python module)."""
    here = os.path.dirname(os.path.abspath(__file__))
    if here not in sys.path:
        sys.path.append(here)
    import emaki_stylize
    return emaki_stylize


class EMAKI_PT_panel(bpy.types.Panel):
    bl_label = "emaki"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "output"

    def draw(self, context):
        col = self.layout.column()
        col.prop(context.scene, "emaki_out")
        col.prop(context.scene, "emaki_samples")
        col.operator(EMAKI_OT_render_passes.bl_idname)
        stylize_module().draw(self.layout, context.scene)


def register():
    bpy.types.Scene.emaki_out = bpy.props.StringProperty(name="Folder", subtype="DIR_PATH",
                                                         default="//emaki_passes/")
    bpy.types.Scene.emaki_samples = bpy.props.IntProperty(name="Samples", default=16, min=1)
    bpy.utils.register_class(EMAKI_OT_render_passes)
    stylize_module().register()
    bpy.utils.register_class(EMAKI_PT_panel)


def unregister():
    bpy.utils.unregister_class(EMAKI_PT_panel)
    stylize_module().unregister()
    bpy.utils.unregister_class(EMAKI_OT_render_passes)
    del bpy.types.Scene.emaki_out
    del bpy.types.Scene.emaki_samples


if __name__ == "__main__":
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        main(argv)
    except ExportError as e:
        print("emaki_passes: error: %s" % e, file=sys.stderr)
        sys.exit(1)
