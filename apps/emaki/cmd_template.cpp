// `emaki template`: the reference sphere's passes and a paint template, or passes fitted to a
// sphere that is already painted (--fit PAINTING --sphere CX,CY,R).
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "apps/emaki/commands.h"
#include "apps/emaki/shot_options.h"
#include "core/error.h"
#include "core/parallel.h"
#include "exemplar/reference_sphere.h"
#include "io/image_io.h"
#include "render/passes.h"
#include "render/renderer.h"

namespace emaki::app {

int run_template(const Args& args) {
  CLI::App app{
      "Renders the reference sphere (a unit sphere standing on a ground plane, lit by the key "
      "light) with the same passes as `emaki render`, and a paint template to paint over: "
      "DIR/reference.exr, DIR/template.png. With --fit, the passes are aligned to a sphere "
      "already painted in PAINTING.",
      "emaki template"};
  std::string out_dir, size = "1024x768", fit, sphere, light = "-1,1,1";
  std::string ground_color = "0.8,0.8,0.8", background = "0,0,0";
  float elevation = 10.0f, fov = 30.0f, softness = 2.0f, outline_width = 1.5f;
  float horizon = NAN;
  int aa = 3, threads = 0;
  bool no_ground = false, previews = false, full_float = false;
  app.add_option("--out", out_dir, "output folder (created if missing)")->required();
  app.add_option("--size", size, "WIDTHxHEIGHT, each in [1, 16384] (ignored with --fit)")
      ->capture_default_str();
  app.add_option("--fit", fit, "a painting of a sphere: passes take its size and --sphere");
  app.add_option("--sphere", sphere,
                 "sphere centre and radius in pixels CX,CY,R (x right, y down); "
                 "default: image centre, radius 30 % of the height; required with --fit");
  app.add_option("--elevation", elevation, "camera degrees above the horizon, [-80, 80]")
      ->check(CLI::Range(-80.0f, 80.0f))
      ->capture_default_str();
  app.add_option("--horizon", horizon,
                 "image row of the ground's horizon; sets the elevation instead of --elevation");
  app.add_option("--fov", fov,
                 "vertical field of view, degrees, [1, 120]; small = nearly orthographic")
      ->check(CLI::Range(1.0f, 120.0f))
      ->capture_default_str();
  app.add_option("--light", light,
                 "direction towards the key light X,Y,Z relative to the camera (x right, y up, z "
                 "towards the viewer)")
      ->capture_default_str();
  app.add_option("--softness", softness, "angular size of the light, degrees, [0, 45]")
      ->check(CLI::Range(0.0f, 45.0f))
      ->capture_default_str();
  app.add_flag("--no-ground", no_ground, "no ground plane (and no cast shadow)");
  app.add_option("--ground-color", ground_color, "linear RGB albedo of the ground, each in [0, 1]")
      ->capture_default_str();
  app.add_option("--background", background, "linear RGB background colour (albedo pass)")
      ->capture_default_str();
  app.add_option("--aa", aa, "supersampling: N x N samples per pixel, [1, 4]")
      ->check(CLI::Range(1, 4))
      ->capture_default_str();
  app.add_option("--outline-width", outline_width, "outline width in pixels, [0, 16]")
      ->check(CLI::Range(0.0f, 16.0f))
      ->capture_default_str();
  app.add_flag("--previews", previews,
               "also write DIR/preview/reference_<pass>.png for every pass");
  app.add_flag("--float", full_float, "32-bit float EXR channels (default: half)");
  app.add_option("--threads", threads, "worker threads, >= 0; 0 = all cores")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  if (parse_cli(app, args)) return 0;
  // CLI11's ranges let nan through; every float option is checked finite and in range here.
  check_number("--elevation", elevation, -80.0f, 80.0f);
  check_number("--fov", fov, 1.0f, 120.0f);
  check_number("--softness", softness, 0.0f, 45.0f);
  check_number("--outline-width", outline_width, 0.0f, 16.0f);
  if (app.count("--horizon") > 0) check_number("--horizon", horizon);
  set_thread_count(threads);

  exemplar::ReferenceSpec spec;
  if (!fit.empty()) {
    if (sphere.empty()) throw Error("--sphere", "is required with --fit");
    const io::AnyImage painting = io::read_image(fit);
    spec.width = painting.width();
    spec.height = painting.height();
  } else {
    parse_size("--size", size, spec.width, spec.height);
  }
  if (!sphere.empty()) {
    const std::vector<float> c = parse_floats("--sphere", sphere, 3);
    if (!(c[2] > 0.0f)) throw Error("--sphere", fmt::format("radius must be > 0, got {}", c[2]));
    spec.center = {c[0], c[1]};
    spec.radius = c[2];
  }
  spec.elevation_deg = elevation;
  spec.horizon_row = horizon;
  spec.fov_deg = fov;
  const std::vector<float> l = parse_floats("--light", light, 3);
  spec.light.direction = {l[0], l[1], l[2]};
  if (glm::length(spec.light.direction) == 0.0f) throw Error("--light", "must not be 0,0,0");
  spec.light.softness_deg = softness;
  spec.ground = !no_ground;
  const std::vector<float> g = parse_floats("--ground-color", ground_color, 3);
  spec.ground_color = {g[0], g[1], g[2]};
  const std::vector<float> b = parse_floats("--background", background, 3);
  spec.background = {b[0], b[1], b[2]};

  const scene::Scene sphere_scene = exemplar::sphere_scene();
  const scene::ShotSpec shot = exemplar::reference_shot(spec);
  render::RenderOptions options;
  options.width = spec.width;
  options.height = spec.height;
  options.aa = aa;
  options.outline_width = outline_width;
  const render::ShotRenderer renderer(sphere_scene, shot, options);

  namespace fs = std::filesystem;
  const fs::path dir(out_dir);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir))
    throw Error("--out", fmt::format("cannot create folder '{}'", out_dir));
  io::check_writable((dir / "reference.exr").string());
  fs::path preview_dir;
  if (previews) {
    preview_dir = dir / "preview";
    fs::create_directories(preview_dir, ec);
    if (!fs::is_directory(preview_dir))
      throw Error("--out", fmt::format("cannot create folder '{}'", preview_dir.string()));
  }
  const Image<float> frame = renderer.render(0);
  write_frame(frame, dir / "reference.exr", preview_dir, "reference", !full_float);
  const Image<float> paint = exemplar::paint_template(frame.cview());
  io::WriteOptions po;
  po.format = io::SampleFormat::kU8;
  io::write_image((dir / "template.png").string(), paint.cview(), po);
  const glm::vec3 circle = exemplar::sphere_circle(spec);
  std::fprintf(stderr, "emaki template: %dx%d, sphere at (%.1f, %.1f) radius %.1f px; wrote %s\n",
               spec.width, spec.height, circle.x, circle.y, circle.z, dir.string().c_str());
  return 0;
}

}  // namespace emaki::app
