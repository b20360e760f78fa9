// Compositing single-colour layers. A stylized layer carries one value per pixel (the "touch":
// the luminance of its exemplar, or one chosen channel) plus the coverage of the mask it was
// synthesized in; colour is applied only here, so changing a colour, a filter or a blend mode
// never needs a new synthesis.
//
// Colour space: layers are coloured on display-referred (sRGB-encoded) values in [0, 1], as a
// painter's layer stack in Krita or Photoshop does; a linear albedo pass is encoded to sRGB
// before it colours a layer, and the paper comes in display-referred. They are blended there
// too, or in a working space the caller converts them to (composite()'s `to_working`).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/image.h"

namespace emaki::composite {

struct Color {
  float r = 0.0f, g = 0.0f, b = 0.0f;
  friend bool operator==(const Color&, const Color&) = default;
};

// Where a layer's colour comes from.
enum class ColorSource {
  kAlbedo,    // the albedo pass (sRGB-encoded), multiplied by the layer's value
  kFlat,      // one colour, multiplied by the layer's value
  kGradient,  // a gradient indexed by the layer's value (the value is not multiplied in)
};

struct GradientStop {
  float position = 0.0f;  // [0, 1], stops sorted by position
  Color color;
};

// How the layer's value turns into its coverage (alpha), on top of the mask's coverage.
enum class AlphaFrom {
  kMask,          // coverage of the synthesis mask only
  kValue,         // mask x value: light touches cover, dark ones let the layers below through
  kInverseValue,  // mask x (1 - value): dark touches (ink, hatching) cover
};

enum class BlendMode { kNormal, kMultiply, kScreen, kOverlay };

// Filters, applied in this order: levels on the value, colouring, tint, hue/saturation, opacity.
struct Filters {
  // Levels: value -> ((value - in_black) / (in_white - in_black))^(1 / gamma), then mapped to
  // [out_black, out_white]. in_black < in_white; gamma > 0.
  float in_black = 0.0f, in_white = 1.0f, gamma = 1.0f;
  float out_black = 0.0f, out_white = 1.0f;
  Color tint{1.0f, 1.0f, 1.0f};  // multiplies the colour
  float hue_deg = 0.0f;          // hue rotation, degrees
  float saturation = 1.0f;       // >= 0; 0 = grey, 1 = unchanged
  float opacity = 1.0f;          // [0, 1], multiplies the coverage
};

struct LayerLook {
  ColorSource source = ColorSource::kFlat;
  Color flat{1.0f, 1.0f, 1.0f};
  std::vector<GradientStop> gradient;  // kGradient: at least one stop
  AlphaFrom alpha_from = AlphaFrom::kMask;
  Filters filters;
  BlendMode blend = BlendMode::kNormal;
};

// One layer to composite. `value`: the layer's value in its first `value_channels` channels and,
// if it has one more, the mask coverage in its last one (a synthesis output with a target mask).
// A 3-channel (not single-colour) layer brings its own colours: its look's colour source is
// ignored and the levels apply to each channel.
struct LayerInput {
  std::string name;
  ImageView<const float> value;
  ImageView<const float> albedo;  // linear RGB, the output size; needed for ColorSource::kAlbedo
  LayerLook look;
  int value_channels = 1;  // 1 or 3
};

// The paper under every layer: a texture tiled from the top-left corner, or a flat colour.
struct Paper {
  ImageView<const float> texture;  // 1 (grey) or >= 3 channels, sRGB-encoded; empty: no texture
  float scale = 1.0f;              // output pixels per texture pixel, > 0
  Color color{1.0f, 1.0f, 1.0f};   // multiplies the texture; alone when there is no texture
  // The paper already made at the output's size, in the working space: what paper_image and
  // composite()'s `to_working` give (a shot's paper is the same on every frame). Empty, or of
  // another size: made by composite().
  ImageView<const float> made;
};

// sRGB transfer functions on one component.
float srgb_encode(float linear);
float srgb_decode(float encoded);

// The touch of a style exemplar: Rec. 709 luma of an RGB(A) image, or channel `channel` (>= 0).
Image<float> touch(ImageView<const float> image, int channel = -1);

// Applies the levels filter to one value.
float apply_levels(float value, const Filters& f);
// The gradient's colour at t (clamped to its end stops; linear between stops).
Color sample_gradient(const std::vector<GradientStop>& gradient, float t);
// Hue rotation (degrees) and saturation scale of an RGB colour (HSV model).
Color hue_saturation(Color c, float hue_deg, float saturation);
// One blend mode on one component: `base` is below, `top` above.
float blend(BlendMode mode, float base, float top);

// The layer coloured: 4 channels, RGB and straight (not premultiplied) alpha.
Image<float> color_layer(const LayerInput& layer, int width, int height);

// The tiled paper, RGB.
Image<float> paper_image(const Paper& paper, int width, int height);

// Converts an image's RGB (its first three channels) in place, e.g. from display-referred values
// to scene-linear ones (colour/colour.h does it; this module knows no colour space). composite()
// calls it from several threads at once, each on its own rows.
using ToWorkingSpace = std::function<void(ImageView<float>)>;

// Paper, then every layer from first (bottom) to last (top). Returns RGBA with alpha 1.
// With `to_working`, the paper and each coloured layer go through it before they are blended,
// and the blending is done on its values (no clamp to [0, 1]). A layer's pixels it does not
// cover (alpha 0) leave what is below them as it is, so only the covered ones are converted
// (a row band's gathered into one row of RGB for each call).
// Throws emaki::Error naming the layer when its sizes do not match or an input it needs is
// missing.
Image<float> composite(const std::vector<LayerInput>& layers, const Paper& paper, int width,
                       int height, const ToWorkingSpace& to_working = {});

}  // namespace emaki::composite
