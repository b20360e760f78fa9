// emaki.render and emaki.template: the guide-pass renderer (render/) and the reference sphere
// (exemplar/) returning numpy arrays, one per pass.
#include <fmt/format.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>

#include "core/limits.h"
#include "core/parallel.h"
#include "exemplar/reference_sphere.h"
#include "io/gltf_loader.h"
#include "python/arrays.h"
#include "python/bindings.h"
#include "python/errors.h"
#include "render/passes.h"
#include "render/renderer.h"

namespace emaki::python {
namespace {

using Vec3 = std::array<float, 3>;
using Size = std::array<int, 2>;

constexpr const char* kRenderDoc =
    R"(render(scene, frame=0, size=(640, 360), *, frames=None, clip=None, fps=24.0, start=0.0, loop=False, aa=2, outline_width=1.5, camera=None, target=None, azimuth=30.0, elevation=15.0, distance=0.0, fov=40.0, gltf_camera=None, light=(-1.0, 1.0, 1.0), light_world=False, softness=2.0, ground=True, threads=0, allow_outside_paths=False)
--

Renders the guide passes of a glTF 2.0 scene at one frame (as `emaki render`).

Args:
    scene: the scene file, .gltf or .glb (str or os.PathLike).
    frame: the frame, [0, 10000000]; frame f is at clip start + start + f / fps.
    size: (width, height) in pixels, each in [1, 16384]. Default (640, 360).
    frames: (first, last): the shot's frame range, which fixes the normalisation boxes
        (position_norm), the automatic camera's framing and camera motion, so that frames
        rendered one call at a time compare; None (default): (frame, frame).
    clip: animation clip by name; None (default): the first clip.
    fps: frames per second, [0.01, 1000]. Default 24.
    start: seconds into the clip of frame 0, >= 0 and within the clip. Default 0.
    loop: play the clip in a loop, so frames may run past its end. Default False.
    aa: supersampling, aa x aa samples per pixel, [1, 4]. Default 2.
    outline_width: outline width in pixels, [0, 16]; 0: no lines. Default 1.5.
    camera: camera position (x, y, z), world, +Y up; needs target. None (default): the
        automatic camera, placed by azimuth / elevation / distance around the subject.
    target: the point the camera looks at; None (default): the subject's centre.
    azimuth: automatic camera, degrees around +Y, 0 = from +Z. Default 30.
    elevation: automatic camera, degrees above the horizon, [-89, 89]. Default 15.
    distance: automatic camera, distance to the target, >= 0; 0 (default): fit the subject.
    fov: vertical field of view, degrees, [1, 170]. Default 40.
    gltf_camera: use the glTF camera on this node index (animated with the clip); None
        (default): the camera above.
    light: direction towards the key light, camera-relative (x right, y up, z towards the
        viewer) unless light_world. Default (-1, 1, 1).
    light_world: light is a world-space direction (+Y up). Default False.
    softness: angular size of the key light, degrees, [0, 45]. Default 2.
    ground: a ground plane under the subject. Default True.
    threads: worker threads, [0, 1024]; 0 (default): all cores.
    allow_outside_paths: let the scene read buffers and images outside its folder. Default
        False.

Returns:
    A dict from pass name (normal, position, position_norm, rest_position, depth, diffuse,
    shadow, albedo, object_id, material_id, outline, motion, alpha; docs/passes.md) to a
    float32 array, HxWxC for passes of 2-3 channels, HxW for one-channel passes.

Raises:
    emaki.FileError: the scene cannot be read.
    emaki.InputError: an argument out of range, a clip or camera node that is not there, a
        frame outside the clip; `subject` names the argument.
)";

constexpr const char* kTemplateDoc =
    R"(template(size=(1024, 768), *, sphere=None, elevation=10.0, horizon=None, fov=30.0, light=(-1.0, 1.0, 1.0), softness=2.0, ground=True, aa=3, outline_width=1.5, threads=0)
--

The reference sphere's passes and paint template (as `emaki template`).

A unit sphere standing on a ground plane under the key light, with the same passes as a shot,
and a paint template to paint over.

Args:
    size: (width, height) in pixels, each in [1, 16384]; for a sphere already painted, the
        painting's size. Default (1024, 768).
    sphere: (cx, cy, r): sphere centre and radius in pixels (x right, y down); None
        (default): image centre, radius 30 % of the height.
    elevation: camera degrees above the horizon, [-80, 80]. Default 10.
    horizon: image row of the ground's horizon; sets the elevation instead. Default None.
    fov: vertical field of view, degrees, [1, 120]. Default 30.
    light: direction towards the key light, camera-relative. Default (-1, 1, 1).
    softness: angular size of the light, degrees, [0, 45]. Default 2.
    ground: a ground plane (and the cast shadow). Default True.
    aa: supersampling, [1, 4]. Default 3.
    outline_width: outline width in pixels, [0, 16]. Default 1.5.
    threads: worker threads, [0, 1024]; 0 (default): all cores.

Returns:
    A dict of the passes (as render()) plus 'template': the paint template, float32 HxWx3,
    sRGB-encoded in [0, 1].

Raises:
    emaki.InputError: an argument out of range, a sphere that does not fit the camera, a
        horizon that cannot be reached; `subject` names the argument.
)";

// Front ends check numbers with their own names (the renderer's own checks are a last line).
void check_range(const char* name, double v, double lo, double hi) {
  if (!(std::isfinite(v) && v >= lo && v <= hi))
    raise_input_error(name, fmt::format("must be a finite number in [{}, {}], got {}", lo, hi, v));
}

glm::vec3 checked_vec3(const char* name, const Vec3& v) {
  for (float x : v) check_range(name, x, -1e9, 1e9);
  return {v[0], v[1], v[2]};
}

void checked_size(const Size& size, int& width, int& height) {
  for (int v : size) check_range("size", v, 1, 16384);
  width = size[0];
  height = size[1];
  translating(ErrorKind::kInput, {}, [&] { check_pixel_budget("size", width, height); });
}

py::dict passes_dict(const Image<float>& frame) {
  py::dict out;
  for (const render::PassInfo& pass : render::pass_table()) {
    Image<float> p(frame.width(), frame.height(), pass.count);
    for (int y = 0; y < frame.height(); ++y)
      for (int x = 0; x < frame.width(); ++x)
        for (int c = 0; c < pass.count; ++c) p(x, y, c) = frame(x, y, pass.first + c);
    out[pass.name] = to_array(p, SampleType::kF32, true);
  }
  return out;
}

struct RenderArgs {
  std::optional<std::array<int, 2>> frames;
  std::optional<std::string> clip;
  float fps, start;
  bool loop;
  int aa;
  float outline_width;
  std::optional<Vec3> camera, target;
  float azimuth, elevation, distance, fov;
  std::optional<int> gltf_camera;
  Vec3 light;
  bool light_world;
  float softness;
  bool ground;
};

scene::ShotSpec shot_spec(int frame, const RenderArgs& a) {
  scene::ShotSpec shot;
  check_range("frame", frame, 0, kMaxFrame);
  shot.first_frame = a.frames ? (*a.frames)[0] : frame;
  shot.last_frame = a.frames ? (*a.frames)[1] : frame;
  if (a.frames && (frame < shot.first_frame || frame > shot.last_frame))
    raise_input_error("frame", fmt::format("{} is outside frames ({}, {})", frame, shot.first_frame,
                                           shot.last_frame));
  check_range("fps", a.fps, render::kMinFps, render::kMaxFps);
  check_range("start", a.start, 0, 1e7);
  shot.fps = a.fps;
  shot.start_time = a.start;
  shot.clip = a.clip.value_or("");
  shot.loop = a.loop;
  scene::CameraSpec& cam = shot.camera;
  check_range("azimuth", a.azimuth, -1e9, 1e9);
  check_range("elevation", a.elevation, -89, 89);
  check_range("distance", a.distance, 0, 1e9);
  check_range("fov", a.fov, 1, 170);
  cam.azimuth_deg = a.azimuth;
  cam.elevation_deg = a.elevation;
  cam.distance = a.distance;
  cam.fov_deg = a.fov;
  if (a.target) cam.target = checked_vec3("target", *a.target), cam.has_target = true;
  if (a.camera) {
    if (!a.target) raise_input_error("camera", "needs target as well");
    cam.mode = scene::CameraSpec::Mode::kLookAt;
    cam.position = checked_vec3("camera", *a.camera);
  }
  if (a.gltf_camera) {
    cam.mode = scene::CameraSpec::Mode::kGltf;
    cam.gltf_node = *a.gltf_camera;
  }
  shot.light.direction = checked_vec3("light", a.light);
  if (glm::length(shot.light.direction) == 0.0f) raise_input_error("light", "must not be 0, 0, 0");
  shot.light.camera_relative = !a.light_world;
  check_range("softness", a.softness, 0, 45);
  shot.light.softness_deg = a.softness;
  shot.ground.enabled = a.ground;
  return shot;
}

py::dict render_frame(const std::filesystem::path& scene_path, int frame, const Size& size,
                      const RenderArgs& args, int threads, bool allow_outside_paths) {
  render::RenderOptions options;
  checked_size(size, options.width, options.height);
  check_range("aa", args.aa, 1, 4);
  check_range("outline_width", args.outline_width, 0, 16);
  check_range("threads", threads, 0, 1024);
  options.aa = args.aa;
  options.outline_width = args.outline_width;
  const scene::ShotSpec shot = shot_spec(frame, args);
  io::GltfOptions gltf;
  gltf.allow_outside_paths = allow_outside_paths;
  const scene::Scene scene =
      without_gil(ErrorKind::kFile, {}, [&] { return io::load_gltf(scene_path.string(), gltf); });
  const char* frames_name = args.frames ? "frames" : "frame";
  const Image<float> image =
      without_gil(ErrorKind::kInput, {{"frames", frames_name}, {"gltf_node", "gltf_camera"}}, [&] {
        const ScopedThreadCount thread_count(threads);
        const render::ShotRenderer renderer(scene, shot, options);
        return renderer.render(frame);
      });
  return passes_dict(image);
}

py::dict render_template(const Size& size, const std::optional<Vec3>& sphere, float elevation,
                         std::optional<float> horizon, float fov, const Vec3& light, float softness,
                         bool ground, int aa, float outline_width, int threads) {
  exemplar::ReferenceSpec spec;
  checked_size(size, spec.width, spec.height);
  if (sphere) {
    checked_vec3("sphere", *sphere);
    if (!((*sphere)[2] > 0.0f)) raise_input_error("sphere", "radius must be > 0");
    spec.center = {(*sphere)[0], (*sphere)[1]};
    spec.radius = (*sphere)[2];
  }
  check_range("elevation", elevation, -80, 80);
  if (horizon) check_range("horizon", *horizon, -1e9, 1e9);
  check_range("fov", fov, 1, 120);
  check_range("softness", softness, 0, 45);
  check_range("aa", aa, 1, 4);
  check_range("outline_width", outline_width, 0, 16);
  check_range("threads", threads, 0, 1024);
  spec.elevation_deg = elevation;
  spec.horizon_row = horizon.value_or(NAN);
  spec.fov_deg = fov;
  spec.light.direction = checked_vec3("light", light);
  if (glm::length(spec.light.direction) == 0.0f) raise_input_error("light", "must not be 0, 0, 0");
  spec.light.softness_deg = softness;
  spec.ground = ground;
  render::RenderOptions options;
  options.width = spec.width;
  options.height = spec.height;
  options.aa = aa;
  options.outline_width = outline_width;
  Image<float> paint;
  const Image<float> frame = without_gil(ErrorKind::kInput, {}, [&] {
    const ScopedThreadCount thread_count(threads);
    const scene::Scene sphere_scene = exemplar::sphere_scene();
    const render::ShotRenderer renderer(sphere_scene, exemplar::reference_shot(spec), options);
    Image<float> f = renderer.render(0);
    paint = exemplar::paint_template(f.cview());
    return f;
  });
  py::dict out = passes_dict(frame);
  out["template"] = to_array(paint, SampleType::kF32, false);
  return out;
}

}  // namespace

void bind_render(py::module_& m) {
  const scene::ShotSpec shot;
  const render::RenderOptions options;
  m.def(
      "render",
      [](const std::filesystem::path& scene, int frame, const Size& size,
         std::optional<std::array<int, 2>> frames, std::optional<std::string> clip, float fps,
         float start, bool loop, int aa, float outline_width, std::optional<Vec3> camera,
         std::optional<Vec3> target, float azimuth, float elevation, float distance, float fov,
         std::optional<int> gltf_camera, const Vec3& light, bool light_world, float softness,
         bool ground, int threads, bool allow_outside_paths) {
        const RenderArgs args{frames,        clip,        fps,    start,       loop,      aa,
                              outline_width, camera,      target, azimuth,     elevation, distance,
                              fov,           gltf_camera, light,  light_world, softness,  ground};
        return render_frame(scene, frame, size, args, threads, allow_outside_paths);
      },
      kRenderDoc, py::arg("scene"), py::arg("frame") = 0,
      py::arg("size") = Size{options.width, options.height}, py::kw_only(),
      py::arg("frames") = py::none(), py::arg("clip") = py::none(), py::arg("fps") = shot.fps,
      py::arg("start") = shot.start_time, py::arg("loop") = shot.loop, py::arg("aa") = options.aa,
      py::arg("outline_width") = options.outline_width, py::arg("camera") = py::none(),
      py::arg("target") = py::none(), py::arg("azimuth") = shot.camera.azimuth_deg,
      py::arg("elevation") = shot.camera.elevation_deg, py::arg("distance") = shot.camera.distance,
      py::arg("fov") = shot.camera.fov_deg, py::arg("gltf_camera") = py::none(),
      py::arg("light") =
          Vec3{shot.light.direction.x, shot.light.direction.y, shot.light.direction.z},
      py::arg("light_world") = false, py::arg("softness") = shot.light.softness_deg,
      py::arg("ground") = shot.ground.enabled, py::arg("threads") = 0,
      py::arg("allow_outside_paths") = false);
  const exemplar::ReferenceSpec spec;
  m.def("template", &render_template, kTemplateDoc, py::arg("size") = Size{spec.width, spec.height},
        py::kw_only(), py::arg("sphere") = py::none(), py::arg("elevation") = spec.elevation_deg,
        py::arg("horizon") = py::none(), py::arg("fov") = spec.fov_deg,
        py::arg("light") =
            Vec3{spec.light.direction.x, spec.light.direction.y, spec.light.direction.z},
        py::arg("softness") = spec.light.softness_deg, py::arg("ground") = spec.ground,
        py::arg("aa") = 3, py::arg("outline_width") = options.outline_width,
        py::arg("threads") = 0);
  // The passes in channel order and their EXR channel names (docs/passes.md), for reading a
  // pass out of a frame's file: read_image(path, channels=pass_channels["normal"]).
  std::vector<std::string> names;
  py::dict channels;
  for (const render::PassInfo& p : render::pass_table()) {
    names.push_back(p.name);
    std::vector<std::string> c;
    for (int k = 0; k < p.count; ++k) c.push_back(std::string(p.name) + "." + p.suffixes[k]);
    channels[p.name] = c;
  }
  m.attr("pass_names") = names;
  m.attr("pass_channels") = channels;
}

}  // namespace emaki::python
