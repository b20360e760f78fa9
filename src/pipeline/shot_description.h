// A shot, as the shot file describes it (docs/shot_file.md is the table of every key): where
// the guide passes come from, the exemplars, the layers and how they are composited, and what
// is written. Plain data, free of I/O: shot/parser.cpp fills it, pipeline/ runs it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "colour/colour.h"
#include "composite/composite.h"
#include "exemplar/reference_sphere.h"
#include "render/renderer.h"
#include "scene/staging.h"
#include "temporal/confidence.h"
#include "temporal/flat_areas.h"

namespace emaki::pipeline {

enum class SourceKind {
  kScene,     // a glTF scene rendered by emaki's own renderer
  kSequence,  // a studio render: one multilayer EXR per frame
};

// How a sequence's channels are named and what they mean.
enum class SourcePreset {
  kEmaki,    // emaki's names and conventions, as `emaki render` and the Blender exporter write
  kBlender,  // a plain Cycles render, converted (store/studio_passes.h)
};

// One pass of passes.h read from a studio render's channels.
struct ChannelMapping {
  std::string pass;                   // a pass name of passes.h ("normal", "albedo", ...)
  std::vector<std::string> channels;  // the file's channel names, as many as the pass has
};

// One asset of a scene assembled in the shot file (source.objects; scene/assembly.h).
struct SceneObject {
  std::string scene;  // the glTF file
  glm::vec3 translate{0.0f}, rotate_deg{0.0f}, scale{1.0f}, velocity{0.0f};
  std::string clip;  // empty: the first clip, if any
  float start = 0.0f;
  bool loop = false;
  int id = 2;  // object_id pass value of everything it draws
};

struct Source {
  SourceKind kind = SourceKind::kScene;
  int first_frame = 0, last_frame = 0;  // inclusive
  int width = 0, height = 0;
  float fps = 24.0f;
  // kScene: one file, or objects assembled into one scene (scene_path empty; shot.clip is then
  // scene::kAssemblyClip)
  std::string scene_path;
  std::vector<SceneObject> objects;
  scene::ShotSpec shot;          // camera, light, ground, clip; frames mirror first/last_frame
  render::RenderOptions render;  // width/height mirror the source's size
  // kSequence
  std::string pattern;  // printf-style with one integer, e.g. renders/frame_%04d.exr
  std::vector<ChannelMapping> channels;        // passes read under other names than emaki's
  SourcePreset preset = SourcePreset::kEmaki;  // `channels` overrides either preset
  std::string view_layer = "ViewLayer";        // kBlender: the view layer's channel prefix
  // kEmaki preset, for other renderers' AOVs: conventions converted on reading.
  bool world_normals = false;  // normal is world-space (turned into camera space)
  bool z_up = false;           // position (and world normals) are Z-up
  bool premultiplied = false;  // continuous passes are premultiplied by alpha
  // The colour space of the colour passes (albedo), converted to the config's scene_linear on
  // reading; data passes (normals, positions, ids, motion) are never converted.
  std::string passes_colorspace = "scene_linear";
  // The size the painted weight maps are (0: the shot's). Not in the shot file: emaki lookdev
  // previews a shot at another size, and its maps are resampled to it.
  int maps_width = 0, maps_height = 0;
};

enum class ExemplarKind {
  kMatcap,    // a painted sphere; its guides are the reference sphere's passes, fitted to it
  kKeyframe,  // a painted frame of the shot (or any scene) with its pass file
};

struct Exemplar {
  std::string name;
  ExemplarKind kind = ExemplarKind::kMatcap;
  std::string painting;
  exemplar::ReferenceSpec reference;  // kMatcap; width/height come from the painting
  int aa = 3;                         // kMatcap: supersampling of the reference passes
  std::string passes;                 // kKeyframe: multilayer EXR with emaki's channel names
  // The painting's colour space (a name or role of the shot's config); it is converted to the
  // config's color_picking space, the painter's values the synthesis sees.
  std::string colorspace = "color_picking";
  // The painting resampled to this share of its size before use (not in the shot file):
  // emaki lookdev's --scale, so that a preview's strokes keep their size against the frame.
  double scale = 1.0;
};

struct GuideSpec {
  std::string pass;  // a pass name of passes.h
  float weight = 1.0f;
  // Optional per-pixel weight over the frame, multiplying `weight`: a pass of each frame (its
  // first channel) or a painted image (the shot's size, its first channel); at most one.
  std::string map_pass = {};
  std::string map_image = {};  // a path
};

// Where a layer is synthesized; the rest of the frame stays empty (transparent).
enum class MaskKind {
  kNone,     // everywhere
  kCovered,  // scene objects and the ground (not the background)
  kObjects,  // scene objects only
  kLines,    // near the outline pass's lines
  kShadow,   // in cast shadow or facing away from the light
  kLit,      // the complement of kShadow over covered pixels
};

struct MaskSpec {
  MaskKind kind = MaskKind::kNone;
  float dilate = 0.0f;     // grow the mask by this many pixels
  float threshold = 0.5f;  // pass value above which a pixel is in the mask
};

enum class AdvectionGuide {
  kPosition,      // the paper's: normalised world position
  kRestPosition,  // rest-pose position plus object ids: follows the material point
};

struct TemporalSpec {
  bool enabled = true;
  float weight = 1.0f;  // weight of the temporal guide pair in the main transfer
  AdvectionGuide guide = AdvectionGuide::kRestPosition;
  // The advection's confidence as the temporal guide's weight map: none where the surface was
  // hidden at t-1 (temporal/confidence.h). Off: full weight everywhere, as before it existed.
  bool confidence = true;
  temporal::ConfidenceParams confidence_params;  // not in the shot file: measured defaults
  // The main transfer's uniformity at temporal frames (the first frame uses SynthSpec's): with
  // the temporal guide holding the layout, the term pushes the exemplar's least used patches
  // into wherever that guide is weakest, where the chain then keeps them (a pale streak behind
  // a moving object at 3500); without it the chain settles into flat, textureless regions. 1000
  // is the middle measured on the example (docs/design/temporal-uniformity.md).
  float uniformity = 1000.0f;
  // More uniformity inside the large flat areas of the layer's own guides at frame t
  // (temporal::flat_areas, weighted by how surely a pixel lies in one): there the guides leave
  // every fitting patch of the painting equally good and a chain without the term settles on a
  // few of them, flat and off in tone. 0: none. Not in the shot file: a kind's default.
  float flat_uniformity = 0.0f;
  temporal::FlatAreaParams flat;
  // The main transfer at a temporal frame starts at the finest pyramid level from the previous
  // frame's field carried along the advection, instead of the whole pyramid from a random field
  // (docs/design/warm-start.md). Off: every frame runs the whole pyramid, as before it existed.
  bool warm_start = true;
  // Which warm-start fields a run keeps on disk: every finished frame's (a forced --frames range
  // inside a finished shot then continues exactly), or the last finished frame's alone (a
  // resumed run still does; a forced range starts its first frame from the whole pyramid).
  bool keep_every_field = true;
  // Both sides of the temporal guide — the exemplar A' and B'adv — low-passed by a Gaussian of
  // this sigma in pixels (0: none): voting and resampling soften B'adv, and matching it against
  // a sharp A' favours the exemplar's flattest patches, so the chain fades frame by frame.
  // Negative: from the frame's size against the painting's (temporal_sharpening()).
  float guide_sigma = -1.0f;
  // The warm start's first estimate: synth::Params::warm_sharp_estimate. Negative: from the
  // frame's size against the painting's (temporal_sharpening()). Off by default: it keeps more
  // grain but flickers more and breaks the hatching's strokes up
  // (docs/design/temporal-sharpening.md).
  float sharp_estimate = 0.0f;
  // The carried field's offsets snapped to the most common one over a (2 r + 1)^2 window
  // (temporal::coherent_field) before the warm start: where the surface turns on screen the
  // carried patches drift apart and the vote blurs them. 0: off. Negative: 3 x the share
  // temporal_sharpening() takes from the frame's size against the painting's, rounded (the
  // `base` kind's default; docs/design/long-shots.md#the-grain-under-a-turning-camera).
  int coherence_radius = 0;
  // A warm start drops the carried field where the temporal guide has no confidence (surface
  // hidden at t-1, the layer's guides changed): those pixels are searched afresh.
  bool reseed = false;
  // The tone anchor (pipeline/tone_anchor.h, docs/design/tone-anchor.md): at each temporal frame
  // a fresh transfer with every input halved `anchor` times (0: off); B'adv's low frequencies
  // (a Gaussian of anchor_sigma pixels at that size) move to the fresh transfer's, so the chain
  // cannot drift lighter or darker, and with anchor_holes the warm start takes the fresh field
  // where the temporal guide has no confidence (uncovered surfaces get the painting's texture,
  // not the leftovers of the carried field). Not in the shot file: measured defaults.
  int anchor = 2;
  float anchor_sigma = 4.0f;
  // The share of the difference moved at each frame (1: all of it); below 1 the anchored tone
  // follows the fresh transfers' as a running mean along the chain, which averages their noise.
  float anchor_rate = 1.0f;
  // Search-vote iterations at the fresh transfer's finest level (-1: the schedule's).
  int anchor_finest_iters = -1;
  bool anchor_holes = true;
  // The share of the way the result's ink moves to the fresh transfer's in its low
  // frequencies (a Gaussian of ink_sigma pixels at the fresh transfer's size; match_ink()), after
  // the main transfer; 0: off.
  float ink_match = 0.0f;
  float ink_sigma = 4.0f;
  // The ink per guide (pipeline/ink_ratio.h): the share of the way each temporal frame's ink is
  // scaled to keep its ratio to the ink of the pass `ink_guide` ("1-PASS": one minus it; empty:
  // the coverage alone) at the chain's first frame's; 0: off.
  float ink_ratio = 0.0f;
  std::string ink_guide;
  int ink_bins = 0;  // 0: the ratio of the means; N: the mean ink per bin of the guide's ink
  // The share of each pixel's move set by the temporal guide's confidence: it takes
  // 1 - w + w x confidence of the frame's factor (0: every pixel alike; 1: uncovered pixels keep
  // their ink).
  float ink_confident = 0.0f;
  // Every ink_refresh frames from the chain's first, the reference is measured again on a fresh
  // transfer of that frame (frame by frame's result), so it follows the shot's own trend; 0: the
  // chain's first frame's alone.
  int ink_refresh = 0;
  // The reference and the factor per object (the object_id pass) where an object covers enough
  // of the frame (pipeline/ink_ratio.h); the other pixels share one factor.
  bool ink_objects = false;
  // Each frame's reference blended between the refresh frames before and after it (at or
  // before the shot's last frame) by its distance to them, so it moves without a step.
  bool ink_blend = false;
  // The warm start's schedule at the finest level: search-vote iterations, and PatchMatch
  // iterations in each.
  int finest_iters = 1;
  int warm_patch_match_iters = 2;
};

struct SynthSpec {
  int patch_size = 5;
  float uniformity = 3500.0f;
  int pyramid_levels = -1;
  int search_vote_iters = -1;
  int patch_match_iters = -1;
  uint64_t seed = 1;
};

// What a layer is for: sets its defaults (shot/kinds.h).
enum class LayerKind { kBase, kOutline, kShadow, kHatching, kCustom };

struct Layer {
  std::string name;
  LayerKind kind = LayerKind::kCustom;
  std::string exemplar;  // an Exemplar's name
  std::vector<GuideSpec> guides;
  SynthSpec synth;
  bool single_colour = true;
  int channel = -1;  // -1: luminance; 0..2: that channel of the painting
  TemporalSpec temporal;
  MaskSpec mask;
  composite::LayerLook look;
  int order = 0;  // compositing order, bottom first; ties keep the file's order
};

// Where the layers are blended (compositing.space).
enum class CompositingSpace {
  kDisplay,      // on display-referred values (the config's color_picking space), as a painter's
                 // layer stack in Krita or Photoshop: today's look, the default
  kSceneLinear,  // each coloured layer and the paper turned scene-linear, then blended
};

struct Compositing {
  std::string paper;  // texture file; empty: flat paper_color
  float paper_scale = 1.0f;
  composite::Color paper_color{1.0f, 1.0f, 1.0f};
  std::string paper_colorspace = "color_picking";  // the scan's colour space
  CompositingSpace space = CompositingSpace::kDisplay;
};

// Colour management (colour/colour.h): the config every colour-space name of the shot is
// looked up in, and the spaces that are not per exemplar. Names may be roles.
struct Colour {
  std::string config;  // colour.config, resolved; empty: none ($OCIO, else the built-in config)
  std::shared_ptr<const colour::Config> ocio;  // opened by the parser; null: the built-in config
  // PNG / MP4 previews and the contact sheet go through this display and view; empty: the
  // config's default display and that display's default view.
  std::string display, view;

  const colour::Config& get() const { return ocio ? *ocio : *colour::Config::builtin(); }
  // The space the composite is in: color_picking (display) or scene_linear.
  std::string working_space(CompositingSpace space) const {
    return space == CompositingSpace::kDisplay ? "color_picking" : "scene_linear";
  }
};

struct Outputs {
  std::string folder;
  // layers/<layer>/<layer>_%04d.exr (float value + mask) is always written: resuming and
  // `emaki composite` read it.
  bool layer_png = true;       // layers/<layer>/<layer>_%04d.png, 16-bit
  bool composite_png = true;   // composite/frame_%04d.png, 16-bit
  bool composite_exr = false;  // composite/frame_%04d.exr
  bool layered_exr = true;     // layered/frame_%04d.exr: every layer and pass
  bool mp4 = true;             // preview.mp4 (ffmpeg, libx264)
  bool contact_sheet = true;   // contact_sheet.png
  int crf = 20;                // libx264 quality, [0, 51]
};

struct Shot {
  std::string path;  // the shot file; relative paths inside it are resolved against its folder
  Source source;
  std::vector<Exemplar> exemplars;
  std::vector<Layer> layers;  // in compositing order (bottom first)
  Compositing compositing;
  Colour colour;
  Outputs outputs;
  int threads = 0;
  int64_t max_pixels = 0;  // limits.max_pixels; 0: none given (the process's budget applies)

  const Exemplar* find_exemplar(const std::string& name) const {
    for (const Exemplar& e : exemplars)
      if (e.name == name) return &e;
    return nullptr;
  }
  const Layer* find_layer(const std::string& name) const {
    for (const Layer& l : layers)
      if (l.name == name) return &l;
    return nullptr;
  }
};

}  // namespace emaki::pipeline
