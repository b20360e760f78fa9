#include "shot/schema.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace emaki::shot {

namespace {

constexpr double kInt32Max = 2147483647.0;
constexpr double kTwoPow40 = 1099511627776.0;

// Rows name only the members they set; the others keep their defaults, which is what GCC's
// -Wmissing-field-initializers would warn of on every row.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
// clang-format off
constexpr KeySpec kSchema[] = {
    {.key = "threads", .type = "integer", .default_value = "`0`", .lo = 0, .hi = 1024, .meaning = "worker threads, 0 = all cores (results do not depend on it)"},
    {.key = "limits.max_pixels", .type = "integer", .default_value = "`268435456` (2^28)", .lo = 1, .hi = kTwoPow40, .range = "[1, 2^40]", .meaning = "the pixel budget: no image emaki reads or makes (frames, paintings, passes, paper) may hold more pixels; `source.size` is checked against it when the shot loads. `--max-pixels N` on the command line wins over it. See [Limits](#limits)"},
    {.key = "colour", .type = "table", .default_value = "—", .meaning = "colour management (OpenColorIO): the config the shot's colour-space, display and view names are looked up in. See [Colour management](#colour-management)"},
    {.key = "colour.config", .type = "string (path)", .default_value = "emaki's built-in config", .meaning = "an OpenColorIO config (`.ocio`), e.g. Blender's `datafiles/colormanagement/config.ocio`; `$OCIO`, when set, wins over it. The built-in config: `scene-linear Rec.709` (reference), `ACEScg`, `sRGB texture`, `raw`; display `sRGB` with views `Standard`, `Filmic`, `Raw`"},
    {.key = "source", .type = "table", .default_value = "required", .meaning = "where each frame's guide passes come from: exactly one of `scene`, `objects` or `sequence`"},
    {.key = "source.scene", .type = "string (path)", .default_value = "—", .meaning = "a glTF 2.0 `.gltf`/`.glb` rendered by emaki's renderer"},
    {.key = "source.objects", .type = "array of tables", .default_value = "—", .meaning = "instead of `scene`: a scene assembled from glTF assets, one `[[source.objects]]` table each, under the shot's camera, light and ground; each object plays its own clip (`source.clip`, `start`, `loop` and `camera.mode = \"gltf\"` are refused). See [Assembled scenes](#assembled-scenes-sourceobjects)"},
    {.key = "source.objects[N].scene", .type = "string (path)", .default_value = "required", .meaning = "the asset, a glTF 2.0 `.gltf`/`.glb` (one file may be placed many times)"},
    {.key = "source.objects[N].translate", .type = "[x, y, z]", .default_value = "`[0, 0, 0]`", .meaning = "where the asset's origin stands at frame 0, world units"},
    {.key = "source.objects[N].rotate", .type = "[x, y, z]", .default_value = "`[0, 0, 0]`", .meaning = "degrees about the X, then the Y, then the Z axis (world axes)"},
    {.key = "source.objects[N].scale", .type = "number or [x, y, z]", .default_value = "`1`", .lo = 1e-6, .hi = 1e6, .range = "each in [1e-6, 1e6]", .meaning = "scale, applied before the rotation"},
    {.key = "source.objects[N].velocity", .type = "[x, y, z]", .default_value = "`[0, 0, 0]`", .meaning = "world units per second: the object moves in a straight line, to `translate` + f / fps x `velocity` at frame f"},
    {.key = "source.objects[N].clip", .type = "string", .default_value = "first clip", .meaning = "the asset's glTF animation to play (an asset without one stands in its rest pose)"},
    {.key = "source.objects[N].start", .type = "number", .default_value = "`0`", .lo = 0, .hi = 10000000.0, .meaning = "seconds into the object's clip at frame 0"},
    {.key = "source.objects[N].loop", .type = "boolean", .default_value = "`false`", .meaning = "play the object's clip in a loop; off, a frame past the clip's end is an error"},
    {.key = "source.objects[N].id", .type = "integer", .default_value = "one past the largest so far (first: 2)", .lo = 2, .hi = 65535, .meaning = "the `object_id` pass value of everything the object draws (0 is the background, 1 the ground); unique across objects"},
    {.key = "source.sequence", .type = "string (pattern)", .default_value = "—", .range = "exactly one `%d`/`%0Nd`, N <= 12", .meaning = "a studio render, one multilayer EXR per frame, e.g. `renders/frame_%04d.exr` (nothing else may follow a `%`)"},
    {.key = "source.frames", .type = "[int, int]", .default_value = "required", .range = "each in [0, 10000000], last >= first, at most 1000000 frames", .meaning = "first and last frame, inclusive"},
    {.key = "source.fps", .type = "number", .default_value = "`24`", .lo = 1, .hi = 240, .meaning = "frames per second: clip time of frame f is clip start + `start` + f / fps; MP4 rate"},
    {.key = "source.size", .type = "[int, int]", .default_value = "required (scene)", .range = "each an integer in [1, 16384]", .meaning = "output width and height in pixels; a sequence takes its first frame's size"},
    {.key = "source.clip", .type = "string", .default_value = "first clip", .meaning = "scene: the glTF animation to play"},
    {.key = "source.start", .type = "number", .default_value = "`0`", .lo = 0, .hi = 10000000.0, .meaning = "scene: seconds into the clip of frame 0 (frame f is at clip start + start + f / fps)"},
    {.key = "source.loop", .type = "boolean", .default_value = "`false`", .meaning = "scene: play the clip in a loop (clip time wraps around its length), so `frames` may run past the clip's end; off, a frame past the end is an error"},
    {.key = "source.aa", .type = "integer", .default_value = "`2`", .lo = 1, .hi = 4, .meaning = "scene: supersampling, N x N samples per pixel"},
    {.key = "source.outline_width", .type = "number", .default_value = "`1.5`", .lo = 0, .hi = 16, .meaning = "scene: outline pass line width in pixels"},
    {.key = "source.crease", .type = "number", .default_value = "`45`", .lo = 0, .hi = 180, .meaning = "scene: angle between faces drawn as a crease line, degrees"},
    {.key = "source.background", .type = "[r, g, b]", .default_value = "`[0, 0, 0]`", .meaning = "scene: background colour of the albedo pass (linear)"},
    {.key = "source.camera.mode", .type = "string", .default_value = "`\"auto\"`", .meaning = "`auto` (framed from azimuth/elevation), `look_at` (position → target), `gltf` (the glTF camera on `gltf_node`)"},
    {.key = "source.camera.position", .type = "[x, y, z]", .default_value = "`[0, 0, 5]`", .meaning = "`look_at`: camera position, world units"},
    {.key = "source.camera.target", .type = "[x, y, z]", .default_value = "bounds centre", .meaning = "point looked at"},
    {.key = "source.camera.azimuth", .type = "number", .default_value = "`30`", .meaning = "`auto`: degrees around +Y, 0 = from +Z"},
    {.key = "source.camera.elevation", .type = "number", .default_value = "`15`", .lo = -89, .hi = 89, .meaning = "`auto`: degrees above the horizon"},
    {.key = "source.camera.distance", .type = "number", .default_value = "`0`", .lo = 0, .hi = 1000000000.0, .meaning = "`auto`: distance to the target, 0 = fit the shot's bounds"},
    {.key = "source.camera.fov", .type = "number", .default_value = "`40`", .lo = 0.1, .hi = 169, .meaning = "vertical field of view, degrees"},
    {.key = "source.camera.orthographic", .type = "boolean", .default_value = "`false`", .meaning = "orthographic projection"},
    {.key = "source.camera.ortho_height", .type = "number", .default_value = "`0`", .lo = 0, .hi = 1000000000.0, .meaning = "orthographic: visible height in world units, 0 = fit"},
    {.key = "source.camera.gltf_node", .type = "integer", .default_value = "`-1`", .lo = -1, .hi = kInt32Max, .range = "-1 or a node index", .meaning = "`gltf`: the node carrying the camera (required in that mode); -1 = none"},
    {.key = "source.camera.orbit", .type = "number", .default_value = "`0`", .meaning = "degrees the camera turns around the target over the frame range"},
    {.key = "source.camera.dolly", .type = "number", .default_value = "`1`", .lo = 0.01, .hi = 100, .meaning = "distance factor reached at the last frame"},
    {.key = "source.camera.pan", .type = "[x, y, z]", .default_value = "`[0, 0, 0]`", .meaning = "camera and target move by this over the frame range"},
    {.key = "source.light.direction", .type = "[x, y, z]", .default_value = "`[-1, 1, 1]`", .meaning = "towards the key light; camera-relative (x right, y up, z to the viewer) unless `world`"},
    {.key = "source.light.world", .type = "boolean", .default_value = "`false`", .meaning = "`direction` is in world space"},
    {.key = "source.light.softness", .type = "number", .default_value = "`2`", .lo = 0, .hi = 45, .meaning = "angular size of the light, degrees: penumbra width"},
    {.key = "source.light.turn", .type = "number", .default_value = "`0`", .lo = -36000, .hi = 36000, .meaning = "degrees the light turns about world +Y over the frame range (linear, like the camera's `orbit`): a moving sun, shadows sweeping across the ground"},
    {.key = "source.ground.enabled", .type = "boolean", .default_value = "`true`", .meaning = "a ground plane under the shot (receives the cast shadow)"},
    {.key = "source.ground.size", .type = "number", .default_value = "`0`", .lo = 0, .hi = 1000000000.0, .meaning = "side of the ground square, 0 = 6 x the shot's bounds"},
    {.key = "source.ground.height", .type = "number", .default_value = "lowest point", .meaning = "y of the ground plane"},
    {.key = "source.ground.color", .type = "[r, g, b]", .default_value = "`[0.8, 0.8, 0.8]`", .range = "each in [0, 1]", .meaning = "linear albedo of the ground"},
    {.key = "source.preset", .type = "string", .default_value = "`\"emaki\"`", .meaning = "sequence: how the file's channels are named and what they mean: `emaki` (emaki's names and conventions, as `emaki render` and `tools/blender/emaki_passes.py` write them; a single-channel pass may end in `.V`) or `blender` (a plain Cycles render with Blender's pass names, converted). See [Studio renders](#studio-renders-channel-presets)"},
    {.key = "source.view_layer", .type = "string", .default_value = "`\"ViewLayer\"`", .meaning = "sequence, `blender`: the view layer whose passes are read (`VIEW_LAYER.Normal.X`, ...)"},
    {.key = "source.channels.PASS", .type = "[string, ...]", .default_value = "the preset's", .meaning = "sequence: the file's channel names for a pass (as many as the pass has), e.g. `normal = [\"N.X\", \"N.Y\", \"N.Z\"]`, read over the preset's; every channel must be in the first frame"},
    {.key = "source.normals", .type = "string", .default_value = "`\"camera\"`", .meaning = "sequence, `emaki`: `world` if the file's normals are world-space (turned into camera space with the camera fitted to the position pass)"},
    {.key = "source.up", .type = "string", .default_value = "`\"y\"`", .meaning = "sequence, `emaki`: `z` if position (and world normals) are Z-up: (x, y, z) becomes (x, z, -y)"},
    {.key = "source.passes_colorspace", .type = "string", .default_value = "`\"scene_linear\"` (role)", .meaning = "sequence: the colour space of the render's albedo, converted to the config's `scene_linear` on reading (e.g. `\"ACEScg\"`), in the frames and in a keyframe exemplar's pass file; data passes (normals, positions, depth, ids, motion, masks) are never converted"},
    {.key = "source.premultiplied", .type = "boolean", .default_value = "`false`", .meaning = "sequence, `emaki`: the continuous passes are premultiplied by alpha (divided by it on reading)"},
    {.key = "exemplars.NAME", .type = "table", .default_value = "at least one", .meaning = "a painting and the guides it was painted over"},
    {.key = "exemplars.NAME.kind", .type = "string", .default_value = "`\"matcap\"`", .meaning = "`matcap`: a painted sphere, its guides are the reference sphere's passes fitted to it (as `emaki template --fit`); `keyframe`: a painted frame with its pass file"},
    {.key = "exemplars.NAME.painting", .type = "string (path)", .default_value = "required", .meaning = "the painting (PNG/EXR/TIFF/JPEG; grey, RGB or RGBA)"},
    {.key = "exemplars.NAME.sphere", .type = "[cx, cy, r]", .default_value = "image centre, 30 % of height", .range = "r > 0", .meaning = "matcap: the painted sphere's centre and radius in pixels (x right, y down)"},
    {.key = "exemplars.NAME.elevation", .type = "number", .default_value = "`10`", .lo = -80, .hi = 80, .meaning = "matcap: camera degrees above the horizon"},
    {.key = "exemplars.NAME.horizon", .type = "number", .default_value = "—", .meaning = "matcap: image row of the ground's horizon (sets the elevation instead)"},
    {.key = "exemplars.NAME.fov", .type = "number", .default_value = "`30`", .lo = 1, .hi = 120, .meaning = "matcap: vertical field of view, degrees"},
    {.key = "exemplars.NAME.light", .type = "[x, y, z]", .default_value = "`[-1, 1, 1]`", .meaning = "matcap: towards the key light, camera-relative; use the shot's light direction"},
    {.key = "exemplars.NAME.softness", .type = "number", .default_value = "`2`", .lo = 0, .hi = 45, .meaning = "matcap: light softness, degrees"},
    {.key = "exemplars.NAME.ground", .type = "boolean", .default_value = "`true`", .meaning = "matcap: the sphere stands on a ground plane (and casts a shadow on it)"},
    {.key = "exemplars.NAME.ground_color", .type = "[r, g, b]", .default_value = "`[0.8, 0.8, 0.8]`", .range = "each in [0, 1]", .meaning = "matcap: ground albedo"},
    {.key = "exemplars.NAME.aa", .type = "integer", .default_value = "`3`", .lo = 1, .hi = 4, .meaning = "matcap: supersampling of the reference passes"},
    {.key = "exemplars.NAME.colorspace", .type = "string", .default_value = "`\"color_picking\"` (role; built-in: `sRGB texture`)", .meaning = "the painting's colour space, converted to the config's `color_picking` space (display-referred values, what the synthesis and the layer colours work on)"},
    {.key = "exemplars.NAME.passes", .type = "string (path)", .default_value = "required (keyframe)", .meaning = "keyframe: multilayer EXR with emaki's channel names, the painting's size; must hold every pass its layers use as guides"},
    {.key = "layers.NAME", .type = "table", .default_value = "at least one", .meaning = "one stylized layer; `kind` sets the defaults marked *kind*"},
    {.key = "layers.NAME.kind", .type = "string", .default_value = "`\"custom\"`", .meaning = "`base` (guides normal 1 + diffuse 1, mask `covered`, colour `albedo`), `shadow` (guides diffuse 1 + shadow 1, mask `shadow` dilated 2 px, flat lilac, `multiply`), `outline` (guides outline 2 + normal 0.5, mask `lines` (threshold 0.1) dilated 3 px, dark ink, alpha `inverse_value`); `shadow` and `outline` also set `temporal_weight = 0` and `temporal_uniformity = 0` (and `shadow` starts the pixels a temporal frame uncovers from a fresh transfer at half size, not a quarter, and keeps the first frame's `uniformity` inside areas where its guides are flat over 129x129 pixels, such as a wall in shadow: docs/design/long-shots.md), and both keep their mean ink per covered pixel at a fresh transfer's, measured every 8 frames (docs/design/ink-ratio.md), `hatching` (dark strokes of a second style: guides normal 1 + diffuse 1.5 + shadow 1, mask `covered`, dark violet ink, alpha `inverse_value`, `multiply`; its ink pinned as the shadow's), `custom` (guides required, no mask, flat white)"},
    {.key = "layers.NAME.exemplar", .type = "string", .default_value = "required", .meaning = "the `[exemplars.NAME]` it is synthesized from"},
    {.key = "layers.NAME.guides.PASS", .type = "number or table", .default_value = "*kind*", .lo = 0, .hi = 1000, .meaning = "a guide pass and its weight, or a table `{ weight = W, map = M }` that gives it a per-pixel weight map; the table replaces the kind's guides. `position`, `depth`, `motion`, `alpha` are refused: they do not mean the same on the exemplar and the shot"},
    {.key = "layers.NAME.guides.PASS.weight", .type = "number", .default_value = "`1`", .lo = 0, .hi = 1000, .meaning = "the guide's weight (the table form)"},
    {.key = "layers.NAME.guides.PASS.map", .type = "string", .default_value = "—", .meaning = "the guide's weight map: a pass of each frame (`diffuse`, `shadow`, `outline`, `alpha`) or a painted image (path; grey, the shot's size). Its first channel, in [0, 1], multiplies the weight at each pixel (0: the guide does not count there)"},
    {.key = "layers.NAME.patch_size", .type = "integer", .default_value = "`5`", .lo = 3, .hi = 31, .range = "odd, [3, 31]", .meaning = "patch side in pixels"},
    {.key = "layers.NAME.uniformity", .type = "number", .default_value = "`3500`", .lo = 0, .hi = 1000000, .meaning = "EbSynth's uniformity weight; 0 disables it"},
    {.key = "layers.NAME.pyramid_levels", .type = "integer", .default_value = "`-1`", .lo = -1, .hi = 32, .range = "-1 or [1, 32]", .meaning = "pyramid levels; -1 = as many as fit"},
    {.key = "layers.NAME.search_vote_iters", .type = "integer", .default_value = "`-1`", .lo = -1, .hi = 100, .meaning = "search/vote iterations per level; -1 = emaki's schedule"},
    {.key = "layers.NAME.patch_match_iters", .type = "integer", .default_value = "`-1`", .lo = -1, .hi = 100, .meaning = "PatchMatch iterations per search; -1 = emaki's schedule"},
    {.key = "layers.NAME.seed", .type = "integer", .default_value = "`1`", .lo = 0, .hi = kInt32Max, .range = "[0, 2^31 - 1]", .meaning = "random seed (each frame and transfer derives its own from it)"},
    {.key = "layers.NAME.single_colour", .type = "boolean", .default_value = "`true`", .meaning = "transfer one channel (the touch) and colour it in compositing; `false` transfers the painting's RGB"},
    {.key = "layers.NAME.channel", .type = "string", .default_value = "`\"luminance\"`", .meaning = "single colour: the touch is `luminance` (Rec. 709 luma) or the painting's `r`, `g` or `b`"},
    {.key = "layers.NAME.temporal", .type = "boolean", .default_value = "`true`", .meaning = "temporal noise reduction: the previous stylized frame, advected to this one, is one more guide"},
    {.key = "layers.NAME.temporal_weight", .type = "number", .default_value = "*kind* (`1`; `shadow`, `outline`: `0`)", .lo = 0, .hi = 1000, .meaning = "weight of that guide; `0`: the warm start alone carries the layer from frame to frame, which kept the shadow's and the outline's ink where the guide faded it (docs/design/temporal-default.md)"},
    {.key = "layers.NAME.temporal_confidence", .type = "boolean", .default_value = "`true`", .meaning = "the temporal guide counts only where the previous frame can help: its weight map is the advection's confidence, 0 where the surface was hidden at t-1 (no ghost of what covered it); `false`: full weight everywhere, as before (docs/design/temporal-confidence.md)"},
    {.key = "layers.NAME.temporal_uniformity", .type = "number", .default_value = "*kind* (`1000`; `shadow`, `outline`: `0`)", .lo = 0, .hi = 1000000, .meaning = "the uniformity term of the main transfer at temporal frames (the first frame uses `uniformity`): it pushes the exemplar's least used patches where the temporal guide is weakest, behind a moving object, where the chain keeps them as a pale streak (clearly at `3500`, faintly at `1000`); on the shadow and outline kinds it lightened the layer over the shot, which `0` does not (docs/design/temporal-default.md). `3500` with `temporal_confidence = false`, `temporal_weight = 1`, `temporal_warm_start = false`: the temporal chain as first built (docs/design/temporal-confidence.md)"},
    {.key = "layers.NAME.temporal_warm_start", .type = "boolean", .default_value = "`true`", .meaning = "a temporal frame's main transfer starts at the finest pyramid level from the previous frame's field carried along the advection, instead of the whole pyramid from a random one: on the example 23-27 % less time per temporal frame, 23 % less flicker and no drift, the judge's style energy 8 % higher (docs/design/warm-start.md); every finished frame's field is kept beside it (`.NAME_0007.nnf`, delta + zlib coded, about 1/8 to 1/30 of 8 bytes a pixel) so a resumed run, or a forced `--frames` range inside a finished shot, continues exactly. `false`: every frame runs the whole pyramid, as before"},
    {.key = "layers.NAME.temporal_fields", .type = "string", .default_value = "`\"every\"`", .meaning = "which warm-start fields a run keeps on disk: `every` finished frame's (a resumed run and a forced `--frames` range inside a finished shot continue exactly; on the bundled example 55 MB for its 48 frames at 960x540, beside 95 MB of layer EXRs and 482 MB of outputs in all) or the `last` finished frame's only (a resumed run still continues exactly; a forced range inside a finished shot starts its first frame from the whole pyramid, so its frames differ from the first run's; the next run after switching to `last` drops the older fields)"},
    {.key = "layers.NAME.advection", .type = "string", .default_value = "`\"rest_position\"`", .meaning = "the advection guide: `position` (normalised world position, the paper's) or `rest_position` (rest-pose position + object id: follows a walking character)"},
    {.key = "layers.NAME.mask", .type = "string", .default_value = "*kind* (`none`)", .meaning = "where the layer is synthesized: `none` (everywhere), `covered` (objects and ground), `objects`, `lines` (near the outline pass's lines), `shadow` (cast shadow or turned from the light), `lit`"},
    {.key = "layers.NAME.mask_dilate", .type = "number", .default_value = "*kind* (`0`)", .lo = 0, .hi = 64, .meaning = "grow the mask by this many pixels"},
    {.key = "layers.NAME.mask_threshold", .type = "number", .default_value = "*kind* (`0.5`)", .lo = 0, .hi = 1, .meaning = "pass value above which a pixel is in the mask (`lines`: outline pass; `shadow`/`lit`: shadow pass)"},
    {.key = "layers.NAME.order", .type = "integer", .default_value = "`0`", .meaning = "compositing order, lower first (under); ties keep the file's order"},
    {.key = "layers.NAME.color", .type = "string or [r, g, b]", .default_value = "*kind*", .range = "each in [0, 1]", .meaning = "the layer's colour: `\"albedo\"` (the albedo pass x the touch), `[r, g, b]` (that colour x the touch), `\"gradient\"` (the gradient indexed by the touch)"},
    {.key = "layers.NAME.gradient", .type = "[[t, r, g, b], ...]", .default_value = "—", .range = "t and colours in [0, 1], sorted by t", .meaning = "gradient stops [t, r, g, b]; giving it alone sets `color = \"gradient\"`"},
    {.key = "layers.NAME.alpha", .type = "string", .default_value = "*kind* (`mask`)", .meaning = "coverage: `mask`, `value` (mask x touch) or `inverse_value` (mask x (1 - touch): dark strokes cover)"},
    {.key = "layers.NAME.blend", .type = "string", .default_value = "*kind* (`normal`)", .meaning = "`normal`, `multiply`, `screen` or `overlay`"},
    {.key = "layers.NAME.levels", .type = "[black, white, gamma]", .default_value = "`[0, 1, 1]`", .range = "black < white, gamma > 0", .meaning = "input levels on the touch"},
    {.key = "layers.NAME.output_levels", .type = "[black, white]", .default_value = "`[0, 1]`", .range = "each in [0, 1]", .meaning = "output levels on the touch"},
    {.key = "layers.NAME.tint", .type = "[r, g, b]", .default_value = "`[1, 1, 1]`", .range = "each in [0, 1]", .meaning = "multiplies the layer's colour"},
    {.key = "layers.NAME.hue", .type = "number", .default_value = "`0`", .lo = -360, .hi = 360, .meaning = "hue rotation, degrees"},
    {.key = "layers.NAME.saturation", .type = "number", .default_value = "`1`", .lo = 0, .hi = 10, .meaning = "saturation factor"},
    {.key = "layers.NAME.opacity", .type = "number", .default_value = "`1`", .lo = 0, .hi = 1, .meaning = "layer opacity"},
    {.key = "compositing", .type = "table", .default_value = "—", .meaning = "what lies under every layer"},
    {.key = "compositing.paper", .type = "string (path)", .default_value = "—", .meaning = "a paper/canvas scan, tiled from the top-left corner; none: flat `paper_color`"},
    {.key = "compositing.paper_scale", .type = "number", .default_value = "`1`", .lo = 0.01, .hi = 100, .meaning = "output pixels per paper pixel"},
    {.key = "compositing.paper_color", .type = "[r, g, b]", .default_value = "`[1, 1, 1]`", .range = "each in [0, 1]", .meaning = "multiplies the paper (or is the paper)"},
    {.key = "compositing.paper_colorspace", .type = "string", .default_value = "`\"color_picking\"` (role; built-in: `sRGB texture`)", .meaning = "the paper scan's colour space, converted to `color_picking`"},
    {.key = "compositing.space", .type = "string", .default_value = "`\"display\"`", .meaning = "where the layers are blended: `display` (on display-referred `color_picking` values, as a painter's layer stack in Krita or Photoshop) or `scene_linear` (each coloured layer and the paper converted to `scene_linear`, then blended: the composite EXRs are scene-linear, for a comp in Nuke). Colours in the shot file are `color_picking` values in both. See [Colour management](#colour-management)"},
    {.key = "outputs", .type = "table", .default_value = "required", .meaning = "what is written, under `folder`"},
    {.key = "outputs.folder", .type = "string (path)", .default_value = "required", .meaning = "output folder (created; must be writable). Always written: `layers/NAME/NAME_%04d.exr` (float touch + mask coverage; resuming and `emaki composite` read them)"},
    {.key = "outputs.layer_png", .type = "boolean", .default_value = "`true`", .meaning = "`layers/NAME/NAME_%04d.png`, 16-bit grey + alpha"},
    {.key = "outputs.composite_png", .type = "boolean", .default_value = "`true`", .meaning = "`composite/frame_%04d.png`, 16-bit RGB"},
    {.key = "outputs.composite_exr", .type = "boolean", .default_value = "`false`", .meaning = "`composite/frame_%04d.exr`, half RGB"},
    {.key = "outputs.layered_exr", .type = "boolean", .default_value = "`true`", .meaning = "`layered/frame_%04d.exr`: every pass, every layer (`layer_NAME.Y`, `layer_NAME.A`; `.R/.G/.B` for a colour layer) and the composite (`composite.R/G/B`), half, for Nuke / After Effects"},
    {.key = "outputs.mp4", .type = "boolean", .default_value = "`true`", .meaning = "`preview.mp4` (ffmpeg, libx264) from the composited PNGs; needs `composite_png`"},
    {.key = "outputs.contact_sheet", .type = "boolean", .default_value = "`true`", .meaning = "`contact_sheet.png`: up to 12 composited frames spread over the shot"},
    {.key = "outputs.display", .type = "string", .default_value = "the config's default (built-in: sRGB)", .meaning = "the display the composited PNGs (and so `preview.mp4` and the contact sheet) are made for"},
    {.key = "outputs.view", .type = "string", .default_value = "the display's default (built-in: Standard)", .meaning = "the view of `display`: built-in `Standard` (the sRGB curve), `Filmic` (a filmic tone scale, ACES 1.0 SDR) or `Raw`"},
    {.key = "outputs.crf", .type = "integer", .default_value = "`20`", .lo = 0, .hi = 51, .meaning = "libx264 quality, lower is better"},
};
// clang-format on
#pragma GCC diagnostic pop

std::string number_text(double v) {
  if (v == std::floor(v) && std::abs(v) < 1e7) return fmt::format("{}", int64_t(v));
  // 1e+07 reads as 1e7.
  const std::string g = fmt::format("{:g}", v);
  const std::size_t e = g.find("e+");
  if (e == std::string::npos) return g;
  const std::size_t digits = g.find_first_not_of('0', e + 2);
  return fmt::format("{}e{}", g.substr(0, e), g.substr(digits));
}

std::string range_text(const KeySpec& k) {
  if (!k.range.empty()) return std::string(k.range);
  if (std::isnan(k.lo)) return "—";
  return fmt::format("[{}, {}]", number_text(k.lo), number_text(k.hi));
}

}  // namespace

std::span<const KeySpec> schema() {
  return kSchema;
}

const KeySpec* find_key(std::string_view key) {
  for (const KeySpec& k : kSchema)
    if (k.key == key) return &k;
  return nullptr;
}

std::vector<std::string> child_keys(std::string_view prefix) {
  std::vector<std::string> out;
  for (const KeySpec& k : kSchema) {
    std::string_view rest = k.key;
    if (!prefix.empty()) {
      if (rest.size() <= prefix.size() + 1 || rest.substr(0, prefix.size()) != prefix ||
          rest[prefix.size()] != '.')
        continue;
      rest.remove_prefix(prefix.size() + 1);
    }
    // "objects[N].scene" is a key under "objects" (an array of tables).
    const std::string child(rest.substr(0, rest.find_first_of(".[")));
    if (std::find(out.begin(), out.end(), child) == out.end()) out.push_back(child);
  }
  return out;
}

std::string schema_markdown() {
  std::string md = "| key | type | default | range | meaning |\n|---|---|---|---|---|\n";
  for (const KeySpec& k : kSchema) {
    const std::string key = k.is_table()                  ? fmt::format("**`[{}]`**", k.key)
                            : k.type == "array of tables" ? fmt::format("**`[[{}]]`**", k.key)
                                                          : fmt::format("`{}`", k.key);
    md += fmt::format("| {} | {} | {} | {} | {} |\n", key, k.type, k.default_value, range_text(k),
                      k.meaning);
  }
  return md;
}

}  // namespace emaki::shot
