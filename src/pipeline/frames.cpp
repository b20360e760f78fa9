#include "pipeline/frames.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "exemplar/reference_sphere.h"
#include "render/passes.h"
#include "render/renderer.h"

namespace emaki::pipeline {

namespace {

class SceneFrames : public FrameSource {
 public:
  SceneFrames(scene::Scene scene, const Source& source)
      : scene_(std::move(scene)), renderer_(scene_, source.shot, source.render) {}
  Image<float> passes(int frame) const override { return renderer_.render(frame); }

 private:
  scene::Scene scene_;  // the renderer keeps a reference: declared first, destroyed last
  render::ShotRenderer renderer_;
};

// Grows a binary mask by a disc of `radius` pixels (separable would be a square; a disc keeps
// line masks round at their ends). Each output row gathers from the rows within reach, so
// bands of rows run in parallel.
Image<float> dilate(const Image<float>& m, float radius) {
  if (radius <= 0.0f) return m.clone();
  const int r = int(std::ceil(radius));
  const int w = m.width(), h = m.height();
  // Per row offset dy, the half-width of the disc.
  std::vector<int> half(2 * r + 1);
  for (int dy = -r; dy <= r; ++dy) {
    int hw = -1;
    for (int dx = 0; dx <= r; ++dx)
      if (float(dx * dx + dy * dy) <= radius * radius) hw = dx;
    half[dy + r] = hw;
  }
  Image<float> out(w, h, 1);
  parallel_rows(h, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int dy = -r; dy <= r; ++dy) {
        const int yy = y + dy, hw = half[dy + r];
        if (yy < 0 || yy >= h || hw < 0) continue;
        for (int x = 0; x < w; ++x) {
          if (m(x, yy) <= 0.5f) continue;
          for (int xx = std::max(0, x - hw); xx <= std::min(w - 1, x + hw); ++xx) out(xx, y) = 1.0f;
        }
      }
  });
  return out;
}

}  // namespace

std::unique_ptr<FrameSource> scene_frames(scene::Scene scene, const Source& source) {
  return std::make_unique<SceneFrames>(std::move(scene), source);
}

Image<float> extract(ImageView<const float> passes, int first, int count) {
  CHECK_LE(first + count, passes.channels);
  Image<float> out(passes.width, passes.height, count);
  const int step = passes.channels, w = passes.width;
  parallel_rows(passes.height, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const float* in = passes.row(y) + first;
      float* o = out.row(y);
      if (count == passes.channels) {
        std::copy(in, in + std::ptrdiff_t(w) * count, o);
      } else if (count == 1) {
        for (int x = 0; x < w; ++x) o[x] = in[std::ptrdiff_t(x) * step];
      } else if (count == 3) {
        for (int x = 0; x < w; ++x, o += 3, in += step) o[0] = in[0], o[1] = in[1], o[2] = in[2];
      } else {
        for (int x = 0; x < w; ++x, o += count, in += step) std::copy(in, in + count, o);
      }
    }
  });
  return out;
}

Image<float> extract_pass(ImageView<const float> passes, const std::string& name) {
  const render::PassInfo* p = render::find_pass(name);
  CHECK(p != nullptr);
  return extract(passes, p->first, p->count);
}

Image<float> layer_mask(ImageView<const float> passes, const MaskSpec& spec) {
  if (spec.kind == MaskKind::kNone) return {};
  Image<float> m(passes.width, passes.height, 1);
  parallel_rows(passes.height, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < passes.width; ++x) {
        const float* p = passes.at(x, y);
        const bool covered = p[render::kAlpha] > 0.5f && p[render::kObjectId] >= 1.0f;
        // In shadow: cast shadow, or the surface turned away from the key light.
        const bool shadowed =
            covered && (p[render::kShadow] > spec.threshold || p[render::kDiffuse] < 0.1f);
        bool in = false;
        switch (spec.kind) {
          case MaskKind::kNone:
            in = true;
            break;
          case MaskKind::kCovered:
            in = covered;
            break;
          case MaskKind::kObjects:
            in = p[render::kAlpha] > 0.5f && p[render::kObjectId] >= 2.0f;
            break;
          case MaskKind::kLines:
            in = p[render::kOutline] > spec.threshold;
            break;
          case MaskKind::kShadow:
            in = shadowed;
            break;
          case MaskKind::kLit:
            in = covered && !shadowed;
            break;
        }
        m(x, y) = in ? 1.0f : 0.0f;
      }
  });
  return dilate(m, spec.dilate);
}

Image<float> matcap_passes(const Exemplar& e, int width, int height) {
  exemplar::ReferenceSpec spec = e.reference;
  spec.width = width;
  spec.height = height;
  const scene::Scene sphere = exemplar::sphere_scene();
  const scene::ShotSpec shot = exemplar::reference_shot(spec);
  render::RenderOptions options;
  options.width = width;
  options.height = height;
  options.aa = e.aa;
  const render::ShotRenderer renderer(sphere, shot, options);
  return renderer.render(0);
}

Image<float> advection_guide(ImageView<const float> passes, AdvectionGuide guide) {
  const bool rest = guide == AdvectionGuide::kRestPosition;
  const int first = rest ? render::kRestPosition : render::kPositionNorm;
  Image<float> out(passes.width, passes.height, rest ? 4 : 3);
  parallel_rows(passes.height, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < passes.width; ++x) {
        const float* p = passes.at(x, y);
        float* o = out.at(x, y);
        for (int c = 0; c < 3; ++c) o[c] = p[first + c];
        // Ids are small integers (0 background, 1 ground, 2.. objects); the engine normalises
        // a float guide by its range, so different objects end up far apart in patch space.
        if (rest) o[3] = p[render::kObjectId];
      }
  });
  return out;
}

}  // namespace emaki::pipeline
