#include "shot/kinds.h"

namespace emaki::shot {

KindDefaults kind_defaults(pipeline::LayerKind kind) {
  KindDefaults d;
  switch (kind) {
    case pipeline::LayerKind::kBase:
      d.guides = {{"normal", 1.0f}, {"diffuse", 1.0f}};
      d.mask = {pipeline::MaskKind::kCovered, 0.0f, 0.5f};
      d.look.source = composite::ColorSource::kAlbedo;
      // Under a turning camera the carried patches drift apart and the vote blurs the grain
      // away (0.62x of frame by frame's texture on the Fox at 960x540); snapped back side by
      // side the chain keeps it, for some flicker; on the hatching's strokes it cost both
      // (docs/design/long-shots.md).
      d.temporal_coherence = true;
      // After the snap one sweep holds the picture: on the four shots of
      // docs/design/long-shots.md flicker within 0.02x of two sweeps' and tone nearer frame by
      // frame's on three of them, for a fifth less time (docs/design/warm-start.md). The other
      // kinds lost texture or flickered more with one (the hatching 0.805x -> 0.753x on the town).
      d.temporal_warm_sweeps = 1;
      break;
    case pipeline::LayerKind::kShadow:
      d.guides = {{"diffuse", 1.0f}, {"shadow", 1.0f}};
      d.mask = {pipeline::MaskKind::kShadow, 2.0f, 0.5f};
      d.look.flat = {0.55f, 0.52f, 0.7f};
      d.look.blend = composite::BlendMode::kMultiply;
      // The warm start alone carries the shadow: a temporal guide and the uniformity term both
      // lightened it frame by frame (docs/design/temporal-default.md).
      d.temporal_weight = 0.0f;
      d.temporal_uniformity = 0.0f;
      // Uncovered pixels start from a fresh transfer at half size, not a quarter: at a quarter
      // the shadow's edge blurs, and where a moving light uncovered ground the layer came out
      // 13 levels of 255 lighter than frame by frame (docs/design/long-shots.md).
      d.temporal_anchor = 1;
      // Large flat areas (a wall in shadow) went flat, grey and darker without the uniformity
      // term; the first frame's term where the guides are flat over 129x129 pixels gives them
      // their texture and tone back and leaves smaller shadows, which flickered with it, as they
      // were (docs/design/long-shots.md).
      d.temporal_flat_uniformity = true;
      // Without a temporal guide the anchor's tone does not reach the layer and its ink walks
      // with the shot's length; pinned to a fresh transfer's every 8 frames it stays within a
      // level of frame by frame's. Only the pixels the chain carried move: moved all alike, the
      // pixels a moving light uncovers came out lighter (docs/design/ink-ratio.md).
      d.temporal_ink_refresh = 8;
      d.temporal_ink_confident = 1.0f;
      // One factor per frame left the shadow on each object far from frame by frame's (the
      // town's Fox 18.5 levels of 255 lighter); per object, with the references blended between
      // refreshes so that no factor steps, it comes near (docs/design/ink-ratio.md).
      d.temporal_ink_objects = true;
      break;
    case pipeline::LayerKind::kOutline:
      d.guides = {{"outline", 2.0f}, {"normal", 0.5f}};
      d.mask = {pipeline::MaskKind::kLines, 3.0f, 0.1f};
      d.look.flat = {0.08f, 0.06f, 0.06f};
      d.look.alpha_from = composite::AlphaFrom::kInverseValue;
      // As the shadow: the temporal guide faded the ink (docs/design/temporal-default.md).
      d.temporal_weight = 0.0f;
      d.temporal_uniformity = 0.0f;
      // As the shadow, each pixel moved half by its confidence: moved by it alone the line
      // flickered more, moved all alike the lines that appear came out lighter.
      d.temporal_ink_refresh = 8;
      d.temporal_ink_confident = 0.5f;
      break;
    case pipeline::LayerKind::kHatching:
      // Dark strokes of a second style over the base: the strokes cover, the paper does not.
      d.guides = {{"normal", 1.0f}, {"diffuse", 1.5f}, {"shadow", 1.0f}};
      d.mask = {pipeline::MaskKind::kCovered, 0.0f, 0.5f};
      d.look.flat = {0.2f, 0.15f, 0.3f};
      d.look.alpha_from = composite::AlphaFrom::kInverseValue;
      d.look.blend = composite::BlendMode::kMultiply;
      // A sparse painting thins out along the chain as the camera closes in, and the quarter-size
      // anchor cannot hold strokes a few pixels wide: pinned as the shadow, the strokes keep
      // more of frame by frame's texture and its tone (docs/design/ink-ratio.md).
      d.temporal_ink_refresh = 8;
      d.temporal_ink_confident = 1.0f;
      break;
    case pipeline::LayerKind::kCustom:
      break;
  }
  return d;
}

}  // namespace emaki::shot
