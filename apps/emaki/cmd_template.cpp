// `emaki template`: the reference sphere's passes and a paint template, or passes fitted to a
// sphere that is already painted (--fit PAINTING --sphere CX,CY,R).
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "apps/emaki/commands.h"
#include "apps/emaki/staging_options.h"
#include "core/error.h"
#include "core/parallel.h"
#include "exemplar/reference_sphere.h"
#include "io/image_io.h"
#include "render/renderer.h"

namespace emaki::app {
namespace {

namespace fs = std::filesystem;

// The command's own options; the shot around the sphere is StagingOptions'.
struct TemplateOptions {
  std::string out_dir, fit, sphere;
  float horizon = NAN;
  bool previews = false, full_float = false;
  StagingOptions shot{StagingSubject::kReferenceSphere};
};

void add_options(CLI::App& app, TemplateOptions& o) {
  app.add_option("--out", o.out_dir, "output folder (created if missing)")->required();
  app.add_option("--fit", o.fit, "a painting of a sphere: passes take its size and --sphere");
  app.add_option("--sphere", o.sphere,
                 "sphere centre and radius in pixels CX,CY,R (x right, y down); "
                 "default: image centre, radius 30 % of the height; required with --fit");
  app.add_option("--horizon", o.horizon,
                 "image row of the ground's horizon; sets the elevation instead of --elevation");
  o.shot.add_to(app);
  app.add_flag("--previews", o.previews,
               "also write DIR/preview/reference_<pass>.png for every pass");
  app.add_flag("--float", o.full_float, "32-bit float EXR channels (default: half)");
}

// The reference sphere as the options ask; its size is the painting's with --fit.
exemplar::ReferenceSpec reference_spec(const TemplateOptions& o, bool horizon_given,
                                       render::RenderOptions& options) {
  exemplar::ReferenceSpec spec;
  if (horizon_given) check_number("--horizon", o.horizon);
  o.shot.resolve(spec, options);
  if (!o.fit.empty()) {
    if (o.sphere.empty()) throw Error("--sphere", "is required with --fit");
    const io::AnyImage painting = io::read_image(o.fit);
    spec.width = painting.width();
    spec.height = painting.height();
  } else {
    parse_size("--size", o.shot.size, spec.width, spec.height);
  }
  if (!o.sphere.empty()) {
    const std::vector<float> c = parse_floats("--sphere", o.sphere, 3);
    if (!(c[2] > 0.0f)) throw Error("--sphere", fmt::format("radius must be > 0, got {}", c[2]));
    spec.center = {c[0], c[1]};
    spec.radius = c[2];
  }
  spec.horizon_row = o.horizon;
  options.width = spec.width;
  options.height = spec.height;
  return spec;
}

}  // namespace

int run_template(const Args& args) {
  CLI::App app{
      "Renders the reference sphere (a unit sphere standing on a ground plane, lit by the key "
      "light) with the same passes as `emaki render`, and a paint template to paint over: "
      "DIR/reference.exr, DIR/template.png. With --fit, the passes are aligned to a sphere "
      "already painted in PAINTING.",
      "emaki template"};
  TemplateOptions o;
  add_options(app, o);
  if (parse_cli(app, args)) return 0;
  const ScopedThreadCount threads(o.shot.threads);
  render::RenderOptions options;
  const exemplar::ReferenceSpec spec = reference_spec(o, app.count("--horizon") > 0, options);
  const scene::Scene sphere_scene = exemplar::sphere_scene();
  const render::ShotRenderer renderer(sphere_scene, exemplar::reference_shot(spec), options);

  const fs::path dir(o.out_dir);
  make_output_dir("--out", dir);
  io::check_writable((dir / "reference.exr").string());
  fs::path preview_dir;
  if (o.previews) {
    preview_dir = dir / "preview";
    make_output_dir("--out", preview_dir);
  }
  const Image<float> frame = renderer.render(0);
  write_frame(frame, dir / "reference.exr", preview_dir, "reference", !o.full_float);
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
