#include "render/renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "core/parallel.h"
#include "render/frame_geometry.h"
#include "render/outline.h"
#include "render/raster.h"
#include "render/shadow_map.h"

namespace emaki::render {

using scene::Bounds;
using namespace detail;

namespace {

// 8K at 3x3 samples per pixel; more would need gigabytes more of sample buffers.
constexpr double kMaxSamples = 7680.0 * 4320.0 * 9.0;
// Frames whose poses bound the shot (see the ShotRenderer constructor).
constexpr int64_t kMaxBoundsFrames = 4096;

Bounds cube_around(const Bounds& b) {
  if (b.empty()) return {glm::vec3(-1.0f), glm::vec3(1.0f)};
  const float side = std::max({b.size().x, b.size().y, b.size().z, 1e-6f});
  return {b.center() - 0.5f * side, b.center() + 0.5f * side};
}

// ---------------------------------------------------------------------------------------------
// The shot's checks, in the order the constructor makes them (the first failure is reported)

// The visibility buffer holds 16 bytes per sample for the whole frame.
void check_sample_count(const RenderOptions& options) {
  const double samples = double(options.width) * options.height * options.aa * options.aa;
  if (samples > kMaxSamples)
    throw Error(Error::Field{"aa"},
                fmt::format("{}x{} pixels with {}x{} samples each need {:.1f} GB of sample "
                            "buffers (limit {:.1f} GB); lower the antialiasing or the size",
                            options.width, options.height, options.aa, options.aa,
                            samples * 16 / 1e9, kMaxSamples * 16 / 1e9));
}

// Front ends check these with their own names; this is the last line for any other caller.
void check_timing(const scene::ShotSpec& shot) {
  if (!(shot.fps >= kMinFps && shot.fps <= kMaxFps))
    throw Error(Error::Field{"fps"},
                fmt::format("must be in [{}, {}], got {}", kMinFps, kMaxFps, shot.fps));
  if (!std::isfinite(shot.start_time) || shot.start_time < 0.0f)
    throw Error(Error::Field{"start"},
                fmt::format("must be a finite number >= 0, got {}", shot.start_time));
}

// The animation the shot plays: the clip it names, else the scene's first, else none (-1).
int find_clip(const scene::Scene& scene, const std::string& clip) {
  if (clip.empty()) return scene.animations.empty() ? -1 : 0;
  const int animation = scene.find_animation(clip);
  if (animation >= 0) return animation;
  // Names come from the scene and the command line: each is echoed capped, and few.
  std::string names;
  for (std::size_t i = 0; i < scene.animations.size() && i < 16; ++i)
    names += (names.empty() ? "'" : ", '") + echo(scene.animations[i].name, 40) + "'";
  if (scene.animations.size() > 16)
    names += fmt::format(", ... ({} more)", scene.animations.size() - 16);
  throw Error(Error::Field{"clip"}, fmt::format("no clip '{}' in the scene (clips: {})", echo(clip),
                                                names.empty() ? "none" : names));
}

// Bounded before any loop over the range: f - 1, (first + last) / 2 and the constructor's loops
// then never overflow, and --frames 2147483647 --loop is refused instead of spinning forever.
void check_frame_range(const scene::ShotSpec& shot) {
  if (shot.first_frame < 0 || shot.last_frame < shot.first_frame || shot.last_frame > kMaxFrame ||
      shot.last_frame - shot.first_frame >= kMaxFrameCount)
    throw Error(Error::Field{"frames"},
                fmt::format("invalid frame range {}-{} (frames in [0, {}], at most {} of them)",
                            shot.first_frame, shot.last_frame, kMaxFrame, kMaxFrameCount));
}

// The start time and, unless the shot loops, every frame lie within the clip.
void check_frames_in_clip(const scene::Animation& a, const scene::ShotSpec& shot) {
  const float duration = a.end - a.start;
  if (!std::isfinite(duration))
    throw Error(Error::Field{"clip"}, fmt::format("clip '{}' has no finite length", echo(a.name)));
  if (shot.start_time > duration)
    throw Error(Error::Field{"start"}, fmt::format("{} s is outside clip '{}' ({:.3f} s long)",
                                                   shot.start_time, echo(a.name), duration));
  // In double and clamped: a clip of 1e30 s must not overflow the int.
  const double frames_in_clip = std::floor((double(duration) - shot.start_time) * shot.fps + 1e-3);
  const int last_frame = int(std::min<double>(frames_in_clip, kMaxFrame));
  if (!shot.loop && shot.last_frame > last_frame)
    throw Error(Error::Field{"frames"},
                fmt::format("frame {} is at {:.3f} s, past the end of clip '{}' "
                            "({:.3f} s long: frames 0-{} at {} fps from {} s; a looping clip may "
                            "run past its end)",
                            shot.last_frame, shot.start_time + shot.last_frame / shot.fps,
                            echo(a.name), duration, last_frame, shot.fps, shot.start_time));
}

void check_camera_node(const scene::Scene& scene, const scene::ShotSpec& shot) {
  if (shot.camera.mode != scene::CameraSpec::Mode::kGltf) return;
  const int n = shot.camera.gltf_node;
  if (n < 0 || n >= int(scene.nodes.size()) || scene.nodes[n].camera < 0)
    throw Error(Error::Field{"gltf_node"}, fmt::format("node {} is not a camera node", n));
}

// ---------------------------------------------------------------------------------------------
// The shot's fixed boxes

// The frames posed to bound the shot: every frame of a range up to kMaxBoundsFrames long (so
// results do not change for any ordinary shot), else kMaxBoundsFrames evenly spread frames and
// `mid`: the work before the first frame renders must not grow with a million-frame range.
std::vector<int> bounds_frames(int first, int last, int mid) {
  const int64_t count = int64_t(last) - first + 1;
  std::vector<int> frames;
  if (count <= kMaxBoundsFrames) {
    for (int f = first; f <= last; ++f) frames.push_back(f);
    return frames;
  }
  for (int64_t k = 0; k < kMaxBoundsFrames; ++k)
    frames.push_back(int(first + (count - 1) * k / (kMaxBoundsFrames - 1)));
  frames.push_back(mid);  // the middle pose frames the camera
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  return frames;
}

// Up to ~20k of a pose's vertices, evenly picked, for the automatic camera to frame.
void add_fit_points(const scene::PosedScene& posed, std::vector<glm::vec3>& points) {
  std::size_t total = 0;
  for (const auto& p : posed.primitives) total += p.world_positions.size();
  const std::size_t step = std::max<std::size_t>(1, total / 20000);
  std::size_t i = 0;
  for (const auto& p : posed.primitives)
    for (const glm::vec3& v : p.world_positions)
      if (i++ % step == 0) points.push_back(v);
}

// ---------------------------------------------------------------------------------------------
// Shading: a pixel's samples grouped by triangle, each group shaded once at its mean
// barycentrics and weighted by its share of the covered samples

struct Hit {
  int32_t tri;
  int count;
  float b1, b2;
};

struct PixelHits {
  Hit hits[16];  // at most aa x aa = 16 triangles
  int n = 0;
  int covered = 0;  // samples with a triangle
};

PixelHits gather_hits(const VisibilityBuffer& vb, int x, int y, int S) {
  PixelHits ph;
  for (int sy = y * S; sy < (y + 1) * S; ++sy)
    for (int sx = x * S; sx < (x + 1) * S; ++sx) {
      const std::size_t i = vb.index(sx, sy);
      const int32_t t = vb.tri[i];
      if (t < 0) continue;
      ++ph.covered;
      int k = 0;
      while (k < ph.n && ph.hits[k].tri != t) ++k;
      if (k == ph.n) ph.hits[ph.n++] = {t, 0, 0.0f, 0.0f};
      ph.hits[k].count++;
      ph.hits[k].b1 += vb.b1[i];
      ph.hits[k].b2 += vb.b2[i];
    }
  return ph;
}

// Ids: the object covering the most samples (background included), then its material covering
// the most samples; ties keep the first in sample order.
void dominant_ids(const FrameGeometry& g, const PixelHits& ph, int background_samples,
                  int& best_object, int& best_material) {
  best_object = 0, best_material = 0;
  int best_count = background_samples;
  for (int k = 0; k < ph.n; ++k) {
    const int id = g.tris[ph.hits[k].tri].object_id;
    int count = 0;
    for (int j = 0; j < ph.n; ++j)
      if (g.tris[ph.hits[j].tri].object_id == id) count += ph.hits[j].count;
    if (count > best_count) best_count = count, best_object = id;
  }
  for (int k = 0, best_m = 0; k < ph.n; ++k) {
    const TriInfo& info = g.tris[ph.hits[k].tri];
    if (info.object_id != best_object) continue;
    int count = 0;
    for (int j = 0; j < ph.n; ++j)
      if (g.tris[ph.hits[j].tri].object_id == best_object &&
          g.tris[ph.hits[j].tri].material_id == info.material_id)
        count += ph.hits[j].count;
    if (count > best_m) best_m = count, best_material = info.material_id;
  }
}

// What every pixel of a frame is shaded with.
struct Shading {
  const scene::Scene& scene;
  const FrameGeometry& g;
  const Projector& proj;
  const Projector& prev_proj;  // the previous frame's camera, for motion
  const ShadowMap& shadow;
  glm::mat3 view_rot;
  glm::vec3 eye;      // camera position (perspective)
  glm::vec3 forward;  // camera axis (orthographic)
  glm::vec3 light;    // towards the key light
};

// The continuous passes of one pixel, summed over its hits.
struct PassSums {
  glm::vec3 normal{0.0f}, position{0.0f}, rest{0.0f}, albedo{0.0f};
  glm::vec2 motion{0.0f};
  float depth = 0.0f, diffuse = 0.0f, shadow_mask = 0.0f;
};

// Base colour x texture of a scene triangle at barycentrics (b0, b1, b2); the ground's colour.
glm::vec3 albedo_of(const Shading& sh, const TriInfo& info, float b0, float b1, float b2,
                    uint32_t i0, uint32_t i1, uint32_t i2) {
  if (info.object_id == kGroundObject) return sh.g.ground_color;
  if (!info.material) return glm::vec3(1.0f);
  glm::vec4 c = info.material->base_color;
  if (info.material->base_color_texture >= 0) {
    const glm::vec2 uv = b0 * sh.g.uv[i0] + b1 * sh.g.uv[i1] + b2 * sh.g.uv[i2];
    c *= sample_texture(sh.scene.textures[info.material->base_color_texture], uv);
  }
  return glm::vec3(c);
}

// Adds one hit, weighted by its share of the covered samples, to the pixel's sums.
void add_hit(const Shading& sh, const Hit& h, float weight, PassSums& s) {
  const FrameGeometry& g = sh.g;
  const TriInfo& info = g.tris[h.tri];
  const float b1 = h.b1 / h.count, b2 = h.b2 / h.count, b0 = 1.0f - b1 - b2;
  const uint32_t i0 = g.indices[3 * h.tri], i1 = g.indices[3 * h.tri + 1],
                 i2 = g.indices[3 * h.tri + 2];
  const glm::vec3 p = b0 * g.pos[i0] + b1 * g.pos[i1] + b2 * g.pos[i2];
  const glm::vec3 pp = b0 * g.prev_pos[i0] + b1 * g.prev_pos[i1] + b2 * g.prev_pos[i2];
  glm::vec3 n = b0 * g.normal[i0] + b1 * g.normal[i1] + b2 * g.normal[i2];
  n = glm::length(n) > 0.0f ? glm::normalize(n) : info.face_normal;
  glm::vec3 fn = info.face_normal;
  // A back face seen from the camera is shaded as the surface the viewer sees.
  const glm::vec3 to_eye = sh.proj.cam.perspective ? sh.eye - p : -sh.forward;
  if (glm::dot(fn, to_eye) < 0.0f) fn = -fn, n = -n;
  s.normal += weight * (sh.view_rot * n);
  s.position += weight * p;
  s.rest += weight * (b0 * g.rest[i0] + b1 * g.rest[i1] + b2 * g.rest[i2]);
  s.depth += weight * -(sh.proj.cam.view * glm::vec4(p, 1.0f)).z;
  s.motion += weight * (sh.prev_proj.pixel(pp) - sh.proj.pixel(p));
  s.albedo += weight * albedo_of(sh, info, b0, b1, b2, i0, i1, i2);
  const float ndl = glm::dot(n, sh.light);
  float vis = 0.0f;
  if (ndl > 0.0f || glm::dot(fn, sh.light) > 0.0f) vis = sh.shadow.visibility(p, fn);
  s.diffuse += weight * std::max(0.0f, ndl) * vis;
  // Cast shadow only: surfaces turned from the light are dark in `diffuse` already.
  s.shadow_mask += weight * (1.0f - vis) * std::clamp(ndl * 10.0f, 0.0f, 1.0f);
}

// Every pass of a pixel with at least one covered sample (S x S samples).
void shade_pixel(const Shading& sh, const PixelHits& ph, int S, const Bounds& position_box,
                 float* o) {
  int best_object, best_material;
  dominant_ids(sh.g, ph, S * S - ph.covered, best_object, best_material);
  PassSums s;
  for (int k = 0; k < ph.n; ++k)
    add_hit(sh, ph.hits[k], float(ph.hits[k].count) / float(ph.covered), s);
  const float len = glm::length(s.normal);
  const glm::vec3 normal = len > 0.0f ? s.normal / len : glm::vec3(0, 0, 1);
  for (int c = 0; c < 3; ++c) {
    o[kNormal + c] = normal[c];
    o[kPosition + c] = s.position[c];
    o[kPositionNorm + c] = normalise_in(position_box, s.position)[c];
    o[kRestPosition + c] = s.rest[c];
    o[kAlbedo + c] = s.albedo[c];
  }
  o[kDepth] = s.depth;
  o[kDiffuse] = s.diffuse;
  o[kShadow] = s.shadow_mask;
  o[kObjectId] = float(best_object);
  o[kMaterialId] = float(best_material);
  o[kMotion] = s.motion.x;
  o[kMotion + 1] = s.motion.y;
  o[kAlpha] = float(ph.covered) / float(S * S);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// ShotRenderer

ShotRenderer::ShotRenderer(const scene::Scene& scene, const scene::ShotSpec& shot,
                           const RenderOptions& options)
    : scene_(scene), shot_(shot), options_(options) {
  CHECK_GT(options_.width, 0);
  CHECK_GT(options_.height, 0);
  options_.aa = std::clamp(options_.aa, 1, 4);
  check_sample_count(options_);
  check_timing(shot_);
  animation_ = find_clip(scene, shot_.clip);
  check_frame_range(shot_);
  if (animation_ >= 0) check_frames_in_clip(scene.animations[animation_], shot_);
  check_camera_node(scene, shot_);
  // The boxes are fixed for the shot, so normalised values compare across frames.
  const int first = shot_.first_frame, last = shot_.last_frame;
  const int mid = first + (last - first) / 2;
  for (const int f : bounds_frames(first, last, mid)) {
    const scene::PosedScene posed = scene::pose_scene(scene, animation_, time_of(float(f)));
    shot_bounds_.add(scene::world_bounds(posed));
    if (f == first) rest_box_ = cube_around(scene::rest_bounds(posed));
    if (f == first || f == mid || f == last) add_fit_points(posed, fit_points_);
  }
  position_box_ = cube_around(shot_bounds_);
  // Just under the lowest point, so an object's flat bottom does not z-fight with the ground.
  ground_height_ = shot_.ground.auto_height && !shot_bounds_.empty()
                       ? shot_bounds_.lo.y - 1e-4f * glm::length(shot_bounds_.size())
                       : shot_.ground.height;
  first_camera_ = camera(float(shot_.first_frame));
  light_ = scene::light_direction(shot_, first_camera_, float(shot_.first_frame));
}

float ShotRenderer::time_of(float frame) const {
  if (animation_ < 0) return shot_.start_time + frame / shot_.fps;
  const scene::Animation& a = scene_.animations[animation_];
  double t = double(shot_.start_time) + double(frame) / shot_.fps;
  const double duration = double(a.end) - a.start;
  // Wrapped in double, so frame f and f + one cycle land on the same clip time.
  if (shot_.loop && duration > 0.0) t -= std::floor(t / duration) * duration;
  return a.start + float(t);
}

scene::ViewCamera ShotRenderer::camera(float frame) const {
  const float aspect = float(options_.width) / float(options_.height);
  scene::Pose pose;
  if (shot_.camera.mode == scene::CameraSpec::Mode::kGltf)
    pose = scene::evaluate_pose(scene_, animation_, time_of(frame));
  return scene::camera_at(shot_, scene_, pose, shot_bounds_, frame, aspect, &fit_points_);
}

Image<float> ShotRenderer::render(int frame) const {
  const int W = options_.width, H = options_.height, S = options_.aa;
  const scene::PosedScene cur = scene::pose_scene(scene_, animation_, time_of(frame));
  const scene::PosedScene prev = scene::pose_scene(scene_, animation_, time_of(frame - 1));
  const FrameGeometry g = build_geometry(scene_, cur, prev, position_box_, rest_box_, shot_.ground,
                                         ground_height_, shot_bounds_);
  Projector proj{camera(float(frame)), float(W) / float(H), W, H};
  Projector prev_proj{camera(float(frame - 1)), float(W) / float(H), W, H};

  VisibilityBuffer vb;
  vb.reset(W * S, H * S, true);
  {
    std::vector<ClipVertex> verts(g.pos.size());
    for (std::size_t v = 0; v < g.pos.size(); ++v) verts[v] = proj.clip(g.pos[v]);
    RasterOptions ro;
    ro.perspective = proj.cam.perspective;
    ro.znear = proj.cam.znear;
    rasterize(verts, g.indices, ro, vb);
  }
  const glm::vec3 light = scene::light_direction(shot_, first_camera_, float(frame));
  const ShadowMap shadow(g, light, shot_.light.softness_deg, options_.shadow_map_size);

  Image<float> out(W, H, kChannelCount);
  const glm::mat3 view_rot(proj.cam.view);
  const glm::vec3 eye = proj.cam.position();
  const glm::vec3 forward = glm::transpose(view_rot) * glm::vec3(0, 0, -1);
  const Shading shading{scene_, g, proj, prev_proj, shadow, view_rot, eye, forward, light};
  parallel_rows(H, 4, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const PixelHits ph = gather_hits(vb, x, y, S);
        float* o = out.at(x, y);
        if (ph.covered > 0) {
          shade_pixel(shading, ph, S, position_box_, o);
        } else {
          for (int c = 0; c < 3; ++c) o[kAlbedo + c] = shot_.background[c];
        }
      }
  });
  draw_outline(vb, g, proj, options_, out);
  return out;
}

float object_coverage(ImageView<const float> frame) {
  double sum = 0.0;
  for (int y = 0; y < frame.height; ++y)
    for (int x = 0; x < frame.width; ++x)
      if (frame(x, y, kObjectId) >= float(kFirstSceneId)) sum += 1.0;
  return float(sum / (double(frame.width) * frame.height));
}

}  // namespace emaki::render
