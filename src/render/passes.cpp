#include "render/passes.h"

#include <algorithm>
#include <cmath>

#include "core/rng.h"

namespace emaki::render {

const std::vector<PassInfo>& pass_table() {
  static const std::vector<PassInfo> table = {
      {"normal", kNormal, 3, "XYZ"},
      {"position", kPosition, 3, "XYZ"},
      {"position_norm", kPositionNorm, 3, "XYZ"},
      {"rest_position", kRestPosition, 3, "XYZ"},
      {"depth", kDepth, 1, "Z"},
      {"diffuse", kDiffuse, 1, "Y"},
      {"shadow", kShadow, 1, "Y"},
      {"albedo", kAlbedo, 3, "RGB"},
      {"object_id", kObjectId, 1, "Y"},
      {"material_id", kMaterialId, 1, "Y"},
      {"outline", kOutline, 1, "Y"},
      {"motion", kMotion, 2, "XY"},
      {"alpha", kAlpha, 1, "A"},
  };
  return table;
}

std::vector<std::string> channel_names() {
  std::vector<std::string> names;
  for (const PassInfo& p : pass_table())
    for (int c = 0; c < p.count; ++c) names.push_back(std::string(p.name) + "." + p.suffixes[c]);
  return names;
}

const PassInfo* find_pass(const std::string& name) {
  for (const PassInfo& p : pass_table())
    if (name == p.name) return &p;
  return nullptr;
}

namespace {
float encode_srgb(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

void hsv(float h, float s, float v, float* rgb) {
  h = h - std::floor(h);
  const float k[3] = {5, 3, 1};
  for (int c = 0; c < 3; ++c) {
    const float t = std::fmod(k[c] + h * 6.0f, 6.0f);
    rgb[c] = v - v * s * std::clamp(std::min(t, 4.0f - t), 0.0f, 1.0f);
  }
}
}  // namespace

Image<float> preview(ImageView<const float> frame, const PassInfo& pass) {
  const int w = frame.width, h = frame.height;
  Image<float> out(w, h, 3);
  // Depth is shown over the range of the scene's objects (the ground can reach the horizon),
  // or of whatever is covered when there are none.
  float lo = 1e30f, hi = -1e30f, all_lo = 1e30f, all_hi = -1e30f, max_motion = 1e-6f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* p = frame.at(x, y);
      if (p[kAlpha] <= 0.0f) continue;
      all_lo = std::min(all_lo, p[kDepth]);
      all_hi = std::max(all_hi, p[kDepth]);
      if (p[kObjectId] >= 2.0f) lo = std::min(lo, p[kDepth]), hi = std::max(hi, p[kDepth]);
      max_motion = std::max(max_motion, std::hypot(p[kMotion], p[kMotion + 1]));
    }
  if (lo > hi) lo = all_lo, hi = all_hi;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float* p = frame.at(x, y);
      const float* v = p + pass.first;
      float* o = out.at(x, y);
      const float a = p[kAlpha];
      switch (pass.first) {
        case kNormal:
          for (int c = 0; c < 3; ++c) o[c] = a > 0 ? 0.5f + 0.5f * v[c] : 0.0f;
          break;
        case kPosition:
        case kPositionNorm:
        case kRestPosition:
          for (int c = 0; c < 3; ++c) o[c] = std::clamp(v[c], 0.0f, 1.0f);
          break;
        case kDepth:
          o[0] = o[1] = o[2] = a > 0 && hi > lo
                                   ? 1.0f - 0.9f * std::clamp((v[0] - lo) / (hi - lo), 0.0f, 1.0f)
                                   : 0.0f;
          break;
        case kAlbedo:
          for (int c = 0; c < 3; ++c) o[c] = encode_srgb(v[c]);
          break;
        case kObjectId:
        case kMaterialId: {
          const int id = int(std::lround(v[0]));
          if (id == 0) {
            o[0] = o[1] = o[2] = 0.0f;
          } else {
            const uint64_t k = hash_key(pass.first, uint64_t(id));
            hsv(float(k & 0xffff) / 65536.0f, 0.55f, 0.95f, o);
          }
          break;
        }
        case kOutline:
          o[0] = o[1] = o[2] = 1.0f - std::clamp(v[0], 0.0f, 1.0f);
          break;
        case kMotion: {
          const float m = std::hypot(v[0], v[1]);
          hsv(std::atan2(v[1], v[0]) / 6.2831853f + 0.5f, std::min(1.0f, m / max_motion), 1.0f, o);
          break;
        }
        default:
          for (int c = 0; c < 3; ++c) o[c] = encode_srgb(v[0]);
          break;
      }
      if (pass.first == kPosition) {
        // World positions have no fixed range; show them like the normalised copy.
        for (int c = 0; c < 3; ++c) o[c] = std::clamp(p[kPositionNorm + c], 0.0f, 1.0f);
      }
    }
  }
  return out;
}

}  // namespace emaki::render
