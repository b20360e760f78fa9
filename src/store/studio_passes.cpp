#include "store/studio_passes.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "core/error.h"
#include "render/passes.h"

namespace emaki::io {

namespace {

// Raw channel indices (blender_channels order).
enum Raw : int {
  kN = 0,
  kP = 3,
  kZ = 6,
  kDiffDir = 7,
  kDiffCol = 10,
  kIndexOb = 13,
  kIndexMa = 14,
  kVector = 15,
  kA = 17,
};
static_assert(kA + 1 == kBlenderChannelCount);

constexpr float kCovered = 1e-4f;  // alpha above which a pixel shows a surface

glm::vec3 yup(float x, float y, float z) {
  return {x, z, -y};
}

// Blender's ids as emaki's: 0 stays background only where nothing is covered.
float id_of(float raw_index, float alpha) {
  if (alpha <= kCovered) return 0.0f;
  const float id = std::round(raw_index);
  return id < 1.0f ? 2.0f : id;
}

// Cyclic Jacobi: eigenvalues (ascending) and eigenvectors (columns) of a symmetric matrix.
template <int N>
void symmetric_eigen(std::array<std::array<double, N>, N> a, std::array<double, N>& values,
                     std::array<std::array<double, N>, N>& vectors) {
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) vectors[i][j] = i == j;
  for (int sweep = 0; sweep < 60; ++sweep) {
    double off = 0.0;
    for (int i = 0; i < N; ++i)
      for (int j = i + 1; j < N; ++j) off += a[i][j] * a[i][j];
    if (off < 1e-30) break;
    for (int p = 0; p < N; ++p)
      for (int q = p + 1; q < N; ++q) {
        if (std::abs(a[p][q]) < 1e-300) continue;
        const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
        const double t =
            (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < N; ++k) {
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < N; ++k) {
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < N; ++k) {
          const double vkp = vectors[k][p], vkq = vectors[k][q];
          vectors[k][p] = c * vkp - s * vkq;
          vectors[k][q] = s * vkp + c * vkq;
        }
      }
  }
  std::array<int, N> order;
  for (int i = 0; i < N; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int x, int y) { return a[x][x] < a[y][y]; });
  std::array<std::array<double, N>, N> sorted;
  for (int j = 0; j < N; ++j) {
    values[j] = a[order[j]][order[j]];
    for (int i = 0; i < N; ++i) sorted[i][j] = vectors[i][order[j]];
  }
  vectors = sorted;
}

// The key light (direction x strength) that best explains DiffDir = N.L on lit pixels, refitted
// once without the pixels the first fit calls shadowed.
glm::vec3 fit_light(const std::vector<glm::vec3>& normals, const std::vector<float>& diffuse) {
  glm::vec3 light(0.0f);
  for (int pass = 0; pass < 2; ++pass) {
    glm::dmat3 ata(0.0);
    glm::dvec3 atb(0.0);
    int used = 0;
    for (std::size_t i = 0; i < normals.size(); ++i) {
      if (pass == 1 && glm::dot(normals[i], light) - diffuse[i] > 0.1f * glm::length(light))
        continue;  // darker than its N.L: in shadow
      const glm::dvec3 n(normals[i]);
      ata += glm::outerProduct(n, n);
      atb += n * double(diffuse[i]);
      ++used;
    }
    if (used < 3 || std::abs(glm::determinant(ata)) < 1e-12) return light;
    light = glm::vec3(glm::inverse(ata) * atb);
  }
  return light;
}

}  // namespace

std::vector<std::string> blender_channels(const std::string& layer) {
  std::vector<std::string> c;
  for (const char* s :
       {"Normal.X", "Normal.Y", "Normal.Z", "Position.X", "Position.Y", "Position.Z", "Depth.Z",
        "DiffDir.R", "DiffDir.G", "DiffDir.B", "DiffCol.R", "DiffCol.G", "DiffCol.B", "IndexOB.X",
        "IndexMA.X", "Vector.X", "Vector.Y", "Combined.A"})
    c.push_back(layer + "." + s);
  return c;
}

void add_blender_bounds(ImageView<const float> raw, glm::vec3& lo, glm::vec3& hi) {
  CHECK_EQ(raw.channels, kBlenderChannelCount);
  for (int y = 0; y < raw.height; ++y)
    for (int x = 0; x < raw.width; ++x) {
      const float* r = raw.at(x, y);
      const float a = r[kA];
      if (a < 0.5f || id_of(r[kIndexOb], a) == 1.0f) continue;
      const glm::vec3 p = yup(r[kP] / a, r[kP + 1] / a, r[kP + 2] / a);
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
}

Cube cube_around(const glm::vec3& lo, const glm::vec3& hi) {
  if (!(lo.x <= hi.x)) return {};
  const glm::vec3 size = hi - lo;
  const float side = std::max({size.x, size.y, size.z, 1e-6f});
  return {0.5f * (lo + hi) - 0.5f * side, side};
}

CameraAxes fit_camera_axes(const std::vector<glm::vec3>& world, const std::vector<glm::vec2>& pixel,
                           const std::string& file) {
  const std::size_t n = world.size();
  if (n < 12)
    throw Error(file, fmt::format("only {} fully covered pixels: too few to recover the camera "
                                  "that turns world-space normals into camera space",
                                  n));
  // Hartley normalisation: centroids at the origin, mean distances sqrt(3) and sqrt(2).
  glm::dvec3 c3(0.0);
  glm::dvec2 c2(0.0);
  for (std::size_t i = 0; i < n; ++i) c3 += glm::dvec3(world[i]), c2 += glm::dvec2(pixel[i]);
  c3 /= double(n);
  c2 /= double(n);
  double d3 = 0.0, d2 = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    d3 += glm::length(glm::dvec3(world[i]) - c3), d2 += glm::length(glm::dvec2(pixel[i]) - c2);
  const double s3 = std::sqrt(3.0) * double(n) / std::max(d3, 1e-300);
  const double s2 = std::sqrt(2.0) * double(n) / std::max(d2, 1e-300);
  // A^T A of the DLT system, accumulated row pair by row pair.
  std::array<std::array<double, 12>, 12> ata{};
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec3 X = (glm::dvec3(world[i]) - c3) * s3;
    const glm::dvec2 u = (glm::dvec2(pixel[i]) - c2) * s2;
    const std::array<double, 4> h = {X.x, X.y, X.z, 1.0};
    for (int row = 0; row < 2; ++row) {
      std::array<double, 12> a{};
      for (int k = 0; k < 4; ++k) {
        a[row * 4 + k] = h[k];
        a[8 + k] = -u[row] * h[k];
      }
      for (int p = 0; p < 12; ++p)
        for (int q = 0; q < 12; ++q) ata[p][q] += a[p] * a[q];
    }
  }
  std::array<double, 12> values;
  std::array<std::array<double, 12>, 12> vectors;
  symmetric_eigen<12>(ata, values, vectors);
  // One exact solution: the smallest eigenvalue stands clear of the next. Points on one plane
  // leave a second (near-)null direction.
  if (!(values[1] > 1e-8 * values[11]) || values[0] > 0.05 * values[1])
    throw Error(file,
                "the visible points do not determine the camera (all on one plane?), so "
                "world-space normals cannot be turned into camera space; render with "
                "tools/blender/emaki_passes.py or give camera-space normals");
  // The 3x3 part's rows in world units (the world normalisation undone). Undoing the pixel
  // normalisation would scale rows 0 and 1 and add multiples of row 2 to them, which changes
  // none of the directions the orthogonalisation below extracts.
  glm::dvec3 m[3];
  double m4[3];
  for (int r = 0; r < 3; ++r) {
    m[r] = glm::dvec3(vectors[r * 4][0], vectors[r * 4 + 1][0], vectors[r * 4 + 2][0]) * s3;
    m4[r] = vectors[r * 4 + 3][0];
  }
  // P is known up to its sign: the third row measures depth, positive in front of the camera.
  const glm::dvec3 X0 = (glm::dvec3(world[0]) - c3) * s3;
  const double w0 = glm::dot(m[2] / s3, X0) + m4[2];
  const double sign = w0 < 0.0 ? -1.0 : 1.0;
  for (auto& r : m) r *= sign;
  glm::dvec3 right, down, forward;
  if (glm::length(m[2]) > 1e-6 * glm::length(m[0])) {
    forward = glm::normalize(m[2]);
    down = glm::normalize(m[1] - glm::dot(m[1], forward) * forward);
    right = glm::normalize(m[0] - glm::dot(m[0], forward) * forward - glm::dot(m[0], down) * down);
  } else {  // orthographic: no perspective row
    down = glm::normalize(m[1]);
    right = glm::normalize(m[0] - glm::dot(m[0], down) * down);
    forward = glm::cross(right, down);
  }
  if (glm::dot(glm::cross(right, down), forward) < 0.0)
    throw Error(file, "the recovered camera is mirrored; cannot turn normals into camera space");
  return {glm::vec3(right), glm::vec3(-down), glm::vec3(-forward)};
}

namespace {

// Per pixel: unpremultiplied values, world position and normal (+Y up, the normal in world
// space until the camera is known), ids. Fully covered pixels on a grid of `step` are sampled
// into world_points / pixels for fitting the camera.
void convert_pixels(ImageView<const float> raw, const Cube& cube, int step, Image<float>& out,
                    std::vector<glm::vec3>& world_points, std::vector<glm::vec2>& pixels) {
  using namespace render;
  const int w = raw.width, h = raw.height;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* r = raw.at(x, y);
      float* o = out.at(x, y);
      const float a = std::clamp(r[kA], 0.0f, 1.0f);
      o[kAlpha] = a;
      if (a <= kCovered) continue;
      const float inv = 1.0f / a;
      const glm::vec3 p = yup(r[kP] * inv, r[kP + 1] * inv, r[kP + 2] * inv);
      const glm::vec3 nrm = yup(r[kN] * inv, r[kN + 1] * inv, r[kN + 2] * inv);
      for (int c = 0; c < 3; ++c) {
        o[kPosition + c] = p[c];
        o[kNormal + c] = nrm[c];  // world space until the camera is known
        o[kAlbedo + c] = r[kDiffCol + c] * inv;
        o[kPositionNorm + c] = (p[c] - cube.lo[c]) / cube.side;
      }
      const float z = r[kZ];
      o[kDepth] = z > 0.0f && z < 1e9f ? z : 0.0f;
      // Not clamped yet: the light's strength is divided out below.
      o[kDiffuse] = std::max(0.0f, (r[kDiffDir] + r[kDiffDir + 1] + r[kDiffDir + 2]) * inv / 3.0f);
      o[kObjectId] = id_of(r[kIndexOb], a);
      o[kMaterialId] = o[kObjectId] == 1.0f && r[kIndexMa] < 0.5f ? 1.0f : id_of(r[kIndexMa], a);
      o[kMotion] = r[kVector] * inv;
      o[kMotion + 1] = -r[kVector + 1] * inv;
      if (a > 0.999f && x % step == 0 && y % step == 0) {
        world_points.push_back(p);
        pixels.push_back({x + 0.5f, y + 0.5f});
      }
    }
}

// World normals into the fitted camera's space. Lit, fully covered pixels on the `step` grid are
// sampled into lit_normals / lit_diffuse for fitting the light.
void normals_to_camera(const CameraAxes& cam, int step, Image<float>& out,
                       std::vector<glm::vec3>& lit_normals, std::vector<float>& lit_diffuse) {
  using namespace render;
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) {
      float* o = out.at(x, y);
      if (o[kAlpha] <= kCovered) continue;
      glm::vec3 nw(o[kNormal], o[kNormal + 1], o[kNormal + 2]);
      if (glm::length(nw) < 1e-6f) continue;
      nw = glm::normalize(nw);
      glm::vec3 nc(glm::dot(nw, cam.right), glm::dot(nw, cam.up), glm::dot(nw, cam.back));
      for (int c = 0; c < 3; ++c) o[kNormal + c] = nc[c];
      if (o[kAlpha] > 0.999f && o[kDiffuse] > 1e-4f && x % step == 0 && y % step == 0) {
        lit_normals.push_back(nc);
        lit_diffuse.push_back(o[kDiffuse]);
      }
    }
}

// DiffDir is the light's strength x N.L x visibility: divided by the fitted light's strength, it
// is emaki's diffuse whatever the sun's strength was; what N.L leaves unlit is the cast shadow.
void diffuse_and_shadow(const glm::vec3& light, Image<float>& out) {
  using namespace render;
  const float strength = glm::length(light);
  if (!(strength > 1e-3f)) return;  // no light found (NaN included)
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) {
      float* o = out.at(x, y);
      if (o[kAlpha] <= kCovered) continue;
      const float ndl = glm::dot(glm::vec3(o[kNormal], o[kNormal + 1], o[kNormal + 2]), light);
      o[kDiffuse] = std::clamp(o[kDiffuse] / strength, 0.0f, 1.0f);
      if (ndl <= 0.0f) continue;
      const float vis = std::clamp(o[kDiffuse] * strength / ndl, 0.0f, 1.0f);
      o[kShadow] = (1.0f - vis) * std::clamp(10.0f * ndl / strength, 0.0f, 1.0f);
    }
}

// Outline: id changes (not ground against background), depth jumps, creases; both sides.
void draw_outlines(Image<float>& out) {
  using namespace render;
  const float crease = std::cos(45.0f * std::numbers::pi_v<float> / 180.0f);
  auto edge = [&](const float* p, const float* q) {
    const bool pc = p[kAlpha] > 0.5f, qc = q[kAlpha] > 0.5f;
    if (p[kObjectId] != q[kObjectId]) {
      const float lo = std::min(p[kObjectId], q[kObjectId]);
      const float hi = std::max(p[kObjectId], q[kObjectId]);
      return !(lo == 0.0f && hi == 1.0f);
    }
    if (!pc || !qc) return false;
    if (p[kObjectId] >= 2.0f && p[kMaterialId] != q[kMaterialId]) return true;
    if (std::abs(p[kDepth] - q[kDepth]) > 0.03f * std::min(p[kDepth], q[kDepth])) return true;
    const glm::vec3 np(p[kNormal], p[kNormal + 1], p[kNormal + 2]);
    const glm::vec3 nq(q[kNormal], q[kNormal + 1], q[kNormal + 2]);
    return glm::dot(np, nq) < crease;
  };
  const int w = out.width(), h = out.height();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* p = out.at(x, y);
      if (x + 1 < w && edge(p, out.at(x + 1, y))) out(x, y, kOutline) = out(x + 1, y, kOutline) = 1;
      if (y + 1 < h && edge(p, out.at(x, y + 1))) out(x, y, kOutline) = out(x, y + 1, kOutline) = 1;
    }
}

}  // namespace

Image<float> blender_to_emaki(ImageView<const float> raw, const Cube& cube,
                              const std::string& file) {
  CHECK_EQ(raw.channels, kBlenderChannelCount);
  using namespace render;
  const int w = raw.width, h = raw.height;
  Image<float> out(w, h, kChannelCount);
  out.fill(0.0f);
  std::vector<glm::vec3> world_points;
  std::vector<glm::vec2> pixels;
  const int step = std::max(1, int(std::sqrt(double(w) * h / 4000.0)));
  convert_pixels(raw, cube, step, out, world_points, pixels);
  for (int c = 0; c < 3; ++c)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) out(x, y, kRestPosition + c) = out(x, y, kPositionNorm + c);

  const CameraAxes cam = fit_camera_axes(world_points, pixels, file);
  std::vector<glm::vec3> lit_normals;
  std::vector<float> lit_diffuse;
  normals_to_camera(cam, step, out, lit_normals, lit_diffuse);
  // Cast shadow from the fitted key light (camera space).
  diffuse_and_shadow(fit_light(lit_normals, lit_diffuse), out);
  draw_outlines(out);
  return out;
}

void apply_conventions(Image<float>& frame, const AovConventions& conv, const std::string& file) {
  using namespace render;
  CHECK_EQ(frame.channels(), kChannelCount);
  const int w = frame.width(), h = frame.height();
  std::vector<glm::vec3> world_points;
  std::vector<glm::vec2> pixels;
  const int step = std::max(1, int(std::sqrt(double(w) * h / 4000.0)));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* o = frame.at(x, y);
      const float a = o[kAlpha];
      if (a <= kCovered) continue;
      if (conv.premultiplied)
        for (int c = 0; c < kChannelCount; ++c)
          if (c < kObjectId || c >= kMotion) {
            if (c != kAlpha) o[c] /= a;
          }
      if (conv.z_up) {
        const glm::vec3 p = yup(o[kPosition], o[kPosition + 1], o[kPosition + 2]);
        for (int c = 0; c < 3; ++c) o[kPosition + c] = p[c];
        if (conv.world_normals) {
          const glm::vec3 n = yup(o[kNormal], o[kNormal + 1], o[kNormal + 2]);
          for (int c = 0; c < 3; ++c) o[kNormal + c] = n[c];
        }
      }
      if (a > 0.999f && x % step == 0 && y % step == 0) {
        world_points.push_back({o[kPosition], o[kPosition + 1], o[kPosition + 2]});
        pixels.push_back({x + 0.5f, y + 0.5f});
      }
    }
  if (!conv.world_normals) return;
  const CameraAxes cam = fit_camera_axes(world_points, pixels, file);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* o = frame.at(x, y);
      const glm::vec3 n(o[kNormal], o[kNormal + 1], o[kNormal + 2]);
      if (o[kAlpha] <= kCovered || glm::length(n) < 1e-6f) continue;
      const glm::vec3 u = glm::normalize(n);
      o[kNormal] = glm::dot(u, cam.right);
      o[kNormal + 1] = glm::dot(u, cam.up);
      o[kNormal + 2] = glm::dot(u, cam.back);
    }
}

}  // namespace emaki::io
