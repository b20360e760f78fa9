// Materials and base-colour textures (Loader members, see gltf_internal.h). Textures are
// decoded only here, when a material uses them, within kMaxTexturePixels over the scene.
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <optional>

#include "core/limits.h"
#include "io/gltf_internal.h"

namespace emaki::io::gltf_detail {

namespace {

float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// tinygltf's decoded 8- or 16-bit grey, grey+alpha, RGB or RGBA pixels as linear float RGBA
// (the colour channels are sRGB-encoded in glTF, alpha is linear).
scene::Texture to_linear_rgba(const tinygltf::Image& img, int comps, int bytes) {
  // An 8-bit level's linear value, computed once per level rather than once per pixel (the
  // same floats: the same expression on the same input).
  std::array<float, 256> linear8{};
  if (bytes == 1)
    for (int i = 0; i < 256; ++i) linear8[i] = srgb_to_linear(i / 255.0f);
  Image<float> rgba(img.width, img.height, 4);
  for (int y = 0; y < img.height; ++y) {
    float* row = rgba.row(y);
    for (int x = 0; x < img.width; ++x) {
      float v[4] = {0, 0, 0, 1};  // RGB linear, alpha as stored
      for (int c = 0; c < comps; ++c) {
        const std::size_t i = (std::size_t(y) * img.width + x) * comps + c;
        const bool colour = c < 3 && !(comps == 2 && c == 1);
        if (bytes == 2) {
          uint16_t u;
          std::memcpy(&u, img.image.data() + 2 * i, 2);
          v[c] = colour ? srgb_to_linear(u / 65535.0f) : u / 65535.0f;
        } else {
          v[c] = colour ? linear8[img.image[i]] : img.image[i] / 255.0f;
        }
      }
      if (comps < 3) {  // grey (+ alpha)
        if (comps == 2) v[3] = v[1];
        v[1] = v[2] = v[0];
      }
      std::memcpy(row + 4 * x, v, sizeof v);
    }
  }
  scene::Texture out;
  out.rgba = std::make_shared<const Image<float>>(std::move(rgba));
  return out;
}

scene::Texture::Wrap wrap_mode(int mode) {
  switch (mode) {
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
      return scene::Texture::Wrap::kClamp;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
      return scene::Texture::Wrap::kMirror;
    default:
      return scene::Texture::Wrap::kRepeat;
  }
}

}  // namespace

void Loader::load_textures_and_materials(Scene& s) {
  texture_map_.assign(m_.textures.size(), -1);
  for (std::size_t mi = 0; mi < m_.materials.size(); ++mi) {
    const tinygltf::Material& mat = m_.materials[mi];
    scene::Material out;
    out.name = mat.name;
    const auto& f = mat.pbrMetallicRoughness.baseColorFactor;
    if (f.size() == 4) {
      for (int c = 0; c < 4; ++c)
        if (!finite_float(f[c]))
          fail(fmt::format("material {} ('{}') has a non-finite baseColorFactor", mi,
                           echo(mat.name)));
      out.base_color = glm::vec4(f[0], f[1], f[2], f[3]);
    }
    const int tex = mat.pbrMetallicRoughness.baseColorTexture.index;
    if (tex >= 0) {
      out.base_color_texture = base_color_texture(s, tex, mat.name);
      out.texcoord = mat.pbrMetallicRoughness.baseColorTexture.texCoord;
    }
    s.materials.push_back(std::move(out));
  }
}

// The scene's index of texture `tex`, decoded on its first use (textures shared by materials are
// decoded once).
int Loader::base_color_texture(Scene& s, int tex, const std::string& material) {
  if (std::size_t(tex) >= m_.textures.size())
    fail(fmt::format("material '{}' refers to texture {}, but the file has {}", echo(material), tex,
                     m_.textures.size()));
  if (texture_map_[tex] >= 0) return texture_map_[tex];
  const tinygltf::Texture& t = m_.textures[tex];
  scene::Texture out = decode_texture(t, tex);
  if (t.sampler >= 0 && std::size_t(t.sampler) < m_.samplers.size()) {
    out.wrap_s = wrap_mode(m_.samplers[t.sampler].wrapS);
    out.wrap_t = wrap_mode(m_.samplers[t.sampler].wrapT);
  }
  s.textures.push_back(std::move(out));
  texture_map_[tex] = int(s.textures.size()) - 1;
  return texture_map_[tex];
}

// Charges the texture's image to kMaxTexturePixels, then decodes it (to 8 or 16 bits RGBA, by
// tinygltf's own decoder) and converts it to linear float.
scene::Texture Loader::decode_texture(const tinygltf::Texture& t, int tex) {
  if (t.source < 0 || std::size_t(t.source) >= m_.images.size())
    fail(fmt::format("texture {} refers to image {}, but the file has {}", tex, t.source,
                     m_.images.size()));
  const tinygltf::Image& encoded = m_.images[t.source];
  const std::string name =
      encoded.uri.empty() ? fmt::format("image {}", t.source) : echo(encoded.uri);
  if (encoded.width <= 0 || encoded.height <= 0 || encoded.image.empty())
    fail(fmt::format("texture {} ({}) did not decode", tex, name));
  const auto pixels = checked_mul<int64_t>(encoded.width, encoded.height);
  const auto total = pixels ? checked_add<int64_t>(texture_pixels_, *pixels) : std::nullopt;
  if (!total || *total > kMaxTexturePixels)
    fail(
        fmt::format("texture {} ({}, {}x{}): the scene's base-colour textures would hold more "
                    "than {} pixels",
                    tex, name, encoded.width, encoded.height, kMaxTexturePixels));
  texture_pixels_ = *total;
  tinygltf::Image img;
  img.name = encoded.name;
  std::string err, warn;
  if (encoded.image.size() > std::size_t(INT32_MAX) ||
      !tinygltf::LoadImageData(&img, t.source, &err, &warn, encoded.width, encoded.height,
                               encoded.image.data(), int(encoded.image.size()), nullptr))
    fail(fmt::format("texture {} ({}) did not decode", tex, name));
  const int comps = img.component;
  const int bytes = img.bits == 16 ? 2 : 1;
  if (img.width != encoded.width || img.height != encoded.height || comps <= 0 || comps > 4 ||
      img.image.size() < std::size_t(img.width) * img.height * comps * bytes)
    fail(fmt::format("texture {} ({}) did not decode: too little pixel data", tex, name));
  return to_linear_rgba(img, comps, bytes);
}

}  // namespace emaki::io::gltf_detail
