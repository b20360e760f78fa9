#include "composite/composite.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "core/shot_keys.h"

namespace emaki::composite {

namespace {
float clamp01(float v) {
  return std::clamp(v, 0.0f, 1.0f);
}

void check_size(const std::string& layer, const char* what, ImageView<const float> v, int width,
                int height) {
  if (v.width != width || v.height != height)
    throw Error(shot_keys::layer(layer), fmt::format("{} is {}x{}, the output is {}x{}", what,
                                                     v.width, v.height, width, height));
}
}  // namespace

float srgb_encode(float l) {
  l = clamp01(l);
  return l <= 0.0031308f ? 12.92f * l : 1.055f * std::pow(l, 1.0f / 2.4f) - 0.055f;
}

float srgb_decode(float e) {
  e = clamp01(e);
  return e <= 0.04045f ? e / 12.92f : std::pow((e + 0.055f) / 1.055f, 2.4f);
}

Image<float> touch(ImageView<const float> image, int channel) {
  CHECK(!image.empty());
  CHECK_LT(channel, image.channels);
  Image<float> out(image.width, image.height, 1);
  const bool rgb = image.channels >= 3;
  parallel_rows(image.height, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < image.width; ++x) {
        const float* p = image.at(x, y);
        float v;
        if (channel >= 0)
          v = p[channel];
        else if (rgb)
          v = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
        else
          v = p[0];
        out(x, y) = v;
      }
  });
  return out;
}

float apply_levels(float v, const Filters& f) {
  float t = (v - f.in_black) / std::max(f.in_white - f.in_black, 1e-6f);
  t = clamp01(t);
  if (f.gamma != 1.0f) t = std::pow(t, 1.0f / f.gamma);
  return f.out_black + t * (f.out_white - f.out_black);
}

Color sample_gradient(const std::vector<GradientStop>& g, float t) {
  CHECK(!g.empty());
  if (t <= g.front().position) return g.front().color;
  if (t >= g.back().position) return g.back().color;
  for (std::size_t i = 1; i < g.size(); ++i) {
    if (t > g[i].position) continue;
    const GradientStop& a = g[i - 1];
    const GradientStop& b = g[i];
    const float span = b.position - a.position;
    const float u = span > 0.0f ? (t - a.position) / span : 1.0f;
    return {a.color.r + u * (b.color.r - a.color.r), a.color.g + u * (b.color.g - a.color.g),
            a.color.b + u * (b.color.b - a.color.b)};
  }
  return g.back().color;
}

Color hue_saturation(Color c, float hue_deg, float saturation) {
  if (hue_deg == 0.0f && saturation == 1.0f) return c;
  // RGB -> HSV
  const float mx = std::max({c.r, c.g, c.b}), mn = std::min({c.r, c.g, c.b});
  const float d = mx - mn;
  float h = 0.0f;
  if (d > 0.0f) {
    if (mx == c.r)
      h = std::fmod((c.g - c.b) / d + 6.0f, 6.0f);
    else if (mx == c.g)
      h = (c.b - c.r) / d + 2.0f;
    else
      h = (c.r - c.g) / d + 4.0f;
  }
  float s = mx > 0.0f ? d / mx : 0.0f;
  const float v = mx;
  h = std::fmod(h + hue_deg / 60.0f, 6.0f);
  if (h < 0.0f) h += 6.0f;
  s = clamp01(s * saturation);
  // HSV -> RGB
  const float cc = v * s;
  const float x = cc * (1.0f - std::abs(std::fmod(h, 2.0f) - 1.0f));
  const float m = v - cc;
  float r = 0, g = 0, b = 0;
  switch (int(h) % 6) {
    case 0:
      r = cc, g = x;
      break;
    case 1:
      r = x, g = cc;
      break;
    case 2:
      g = cc, b = x;
      break;
    case 3:
      g = x, b = cc;
      break;
    case 4:
      r = x, b = cc;
      break;
    default:
      r = cc, b = x;
      break;
  }
  return {r + m, g + m, b + m};
}

float blend(BlendMode mode, float a, float b) {
  switch (mode) {
    case BlendMode::kNormal:
      return b;
    case BlendMode::kMultiply:
      return a * b;
    case BlendMode::kScreen:
      return 1.0f - (1.0f - a) * (1.0f - b);
    case BlendMode::kOverlay:
      return a < 0.5f ? 2.0f * a * b : 1.0f - 2.0f * (1.0f - a) * (1.0f - b);
  }
  return b;
}

Image<float> color_layer(const LayerInput& layer, int width, int height) {
  const LayerLook& look = layer.look;
  check_size(layer.name, "its value image", layer.value, width, height);
  if (look.source == ColorSource::kAlbedo) {
    if (layer.albedo.empty())
      throw Error(shot_keys::layer_key(layer.name, shot_keys::kColor),
                  "'albedo' needs the albedo pass, which this source does not have");
    check_size(layer.name, "the albedo pass", layer.albedo, width, height);
    CHECK_GE(layer.albedo.channels, 3);
  }
  if (look.source == ColorSource::kGradient && look.gradient.empty())
    throw Error(shot_keys::layer_key(layer.name, shot_keys::kGradient), "needs at least one stop");
  const Filters& f = look.filters;
  const int n = layer.value_channels;
  CHECK(n == 1 || n == 3);
  CHECK_GE(layer.value.channels, n);
  const bool has_mask = layer.value.channels > n;
  Image<float> out(width, height, 4);
  parallel_rows(height, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x) {
        const float* p = layer.value.at(x, y);
        const float mask = has_mask ? clamp01(p[layer.value.channels - 1]) : 1.0f;
        const float v = apply_levels(clamp01(p[0]), f);
        Color c;
        if (n == 3) {
          c = {apply_levels(clamp01(p[0]), f), apply_levels(clamp01(p[1]), f),
               apply_levels(clamp01(p[2]), f)};
        } else
          switch (look.source) {
            case ColorSource::kAlbedo: {
              const float* a = layer.albedo.at(x, y);
              c = {srgb_encode(a[0]) * v, srgb_encode(a[1]) * v, srgb_encode(a[2]) * v};
              break;
            }
            case ColorSource::kFlat:
              c = {look.flat.r * v, look.flat.g * v, look.flat.b * v};
              break;
            case ColorSource::kGradient:
              c = sample_gradient(look.gradient, v);
              break;
          }
        c = {c.r * f.tint.r, c.g * f.tint.g, c.b * f.tint.b};
        c = hue_saturation(c, f.hue_deg, f.saturation);
        // A colour layer's value, for coverage, is its luma.
        const float cov = n == 3 ? 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b : v;
        float alpha = mask;
        if (look.alpha_from == AlphaFrom::kValue) alpha *= cov;
        if (look.alpha_from == AlphaFrom::kInverseValue) alpha *= 1.0f - cov;
        float* o = out.at(x, y);
        o[0] = clamp01(c.r);
        o[1] = clamp01(c.g);
        o[2] = clamp01(c.b);
        o[3] = clamp01(alpha * f.opacity);
      }
  });
  return out;
}

Image<float> paper_image(const Paper& paper, int width, int height) {
  Image<float> out(width, height, 3);
  const ImageView<const float> t = paper.texture;
  if (paper.scale <= 0.0f) throw Error(shot_keys::kPaperScale, "must be > 0");
  parallel_rows(height, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x) {
        float rgb[3] = {1.0f, 1.0f, 1.0f};
        if (!t.empty()) {
          // Bilinear with wrap-around, so a tileable scan stays seamless at any scale.
          const float u = (x + 0.5f) / paper.scale - 0.5f, v = (y + 0.5f) / paper.scale - 0.5f;
          const float fu = std::floor(u), fv = std::floor(v);
          const float wu = u - fu, wv = v - fv;
          auto wrap = [](int i, int n) { return ((i % n) + n) % n; };
          const int x0 = wrap(int(fu), t.width), x1 = wrap(int(fu) + 1, t.width);
          const int yy0 = wrap(int(fv), t.height), yy1 = wrap(int(fv) + 1, t.height);
          for (int c = 0; c < 3; ++c) {
            const int ch = t.channels >= 3 ? c : 0;
            rgb[c] = (1 - wv) * ((1 - wu) * t(x0, yy0, ch) + wu * t(x1, yy0, ch)) +
                     wv * ((1 - wu) * t(x0, yy1, ch) + wu * t(x1, yy1, ch));
          }
        }
        float* o = out.at(x, y);
        o[0] = clamp01(rgb[0] * paper.color.r);
        o[1] = clamp01(rgb[1] * paper.color.g);
        o[2] = clamp01(rgb[2] * paper.color.b);
      }
  });
  return out;
}

namespace {

// `to_working` on the pixels of `rgba` with alpha > 0: a row band's are gathered into one row
// of RGB (a scratch buffer per thread), converted, put back. Each pixel's conversion is its
// own, so this gives what converting all of them gives where it matters. The conversion runs
// isolated: were it to run parallel work, this thread must not take another band meanwhile and
// overwrite the scratch.
void to_working_where_covered(ImageView<float> rgba, const ToWorkingSpace& to_working) {
  parallel_rows(rgba.height, 16, [&](int y0, int y1) {
    thread_local std::vector<float*> where;
    thread_local std::vector<float> rgb;
    where.clear();
    rgb.clear();
    for (int y = y0; y < y1; ++y) {
      float* p = rgba.row(y);
      for (int x = 0; x < rgba.width; ++x, p += rgba.channels)
        if (p[3] > 0.0f) {
          where.push_back(p);
          rgb.insert(rgb.end(), p, p + 3);
        }
    }
    if (where.empty()) return;
    const int n = int(where.size());
    isolated([&] { to_working(ImageView<float>{rgb.data(), n, 1, 3, std::ptrdiff_t(n) * 3}); });
    for (int i = 0; i < n; ++i)
      std::copy_n(rgb.data() + std::ptrdiff_t(i) * 3, 3, where[std::size_t(i)]);
  });
}

}  // namespace

Image<float> composite(const std::vector<LayerInput>& layers, const Paper& paper, int width,
                       int height, const ToWorkingSpace& to_working) {
  Image<float> made;
  ImageView<const float> base = paper.made;
  if (base.empty() || base.width != width || base.height != height || base.channels < 3) {
    made = paper_image(paper, width, height);
    if (to_working) to_working(made.view());
    base = made.cview();
  }
  Image<float> out(width, height, 4);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) out(x, y, c) = base(x, y, c);
      out(x, y, 3) = 1.0f;
    }
  for (const LayerInput& layer : layers) {
    Image<float> rgba = color_layer(layer, width, height);
    if (to_working) to_working_where_covered(rgba.view(), to_working);
    const BlendMode mode = layer.look.blend;
    parallel_rows(height, 16, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < width; ++x) {
          const float* s = rgba.at(x, y);
          float* d = out.at(x, y);
          const float a = s[3];
          for (int c = 0; c < 3; ++c) d[c] = d[c] + a * (blend(mode, d[c], s[c]) - d[c]);
        }
    });
  }
  return out;
}

}  // namespace emaki::composite
