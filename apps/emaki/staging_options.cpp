// The options `emaki render` and `emaki template` share, and the helpers every command uses.
#include "apps/emaki/staging_options.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/check.h"
#include "core/error.h"
#include "core/limits.h"
#include "io/image_io.h"
#include "render/passes.h"

namespace emaki::app {
namespace {

// What differs between the subjects, side by side: defaults, bounds and wording. Everything
// else (the other options, their defaults and help) is the same for both.
struct SubjectTraits {
  const char* size;
  int aa;
  float elevation, max_elevation;
  float fov, max_fov;
  const char* size_help;
  const char* elevation_help;
  const char* fov_help;
  const char* light_help;
  const char* softness_help;
  const char* no_ground_help;
  const char* outline_width_help;
};

constexpr SubjectTraits kSceneTraits{
    .size = "640x360",
    .aa = 2,
    .elevation = scene::kDefaultAutoElevationDeg,
    .max_elevation = 89.0f,
    .fov = 40.0f,
    .max_fov = 170.0f,
    .size_help = "output size WIDTHxHEIGHT, each in [1, 16384]",
    .elevation_help = "automatic camera: degrees above the horizon, [-89, 89]",
    .fov_help = "vertical field of view, degrees, [1, 170]",
    .light_help =
        "direction towards the key light X,Y,Z, relative to the camera (x right, y up, z towards "
        "the viewer) unless --light-world",
    .softness_help = "angular size of the key light in degrees (shadow penumbra), [0, 45]",
    .no_ground_help = "no ground plane",
    .outline_width_help = "outline width in pixels, [0, 16]; 0 = none",
};

// exemplar::reference_shot's bounds: the sphere seen from at most 80 degrees above or below
// the horizon, through a field of view of at most 120 degrees.
constexpr SubjectTraits kReferenceSphereTraits{
    .size = "1024x768",
    .aa = 3,
    .elevation = exemplar::kDefaultReferenceElevationDeg,
    .max_elevation = 80.0f,
    .fov = 30.0f,
    .max_fov = 120.0f,
    .size_help = "WIDTHxHEIGHT, each in [1, 16384] (ignored with --fit)",
    .elevation_help = "camera degrees above the horizon, [-80, 80]",
    .fov_help = "vertical field of view, degrees, [1, 120]; small = nearly orthographic",
    .light_help =
        "direction towards the key light X,Y,Z relative to the camera (x right, y up, z towards "
        "the viewer)",
    .softness_help = "angular size of the light, degrees, [0, 45]",
    .no_ground_help = "no ground plane (and no cast shadow)",
    .outline_width_help = "outline width in pixels, [0, 16]",
};

const SubjectTraits& traits(StagingSubject subject) {
  return subject == StagingSubject::kScene ? kSceneTraits : kReferenceSphereTraits;
}

}  // namespace

StagingOptions::StagingOptions(StagingSubject s)
    : subject(s),
      size(traits(s).size),
      aa(traits(s).aa),
      elevation(traits(s).elevation),
      fov(traits(s).fov) {}

void check_number(const std::string& option, float value, float lo, float hi) {
  if (!(std::isfinite(value) && value >= lo && value <= hi))
    throw Error(option, fmt::format("must be a finite number in [{}, {}], got {}", lo, hi, value));
}

std::vector<float> parse_floats(const std::string& option, const std::string& text, int count) {
  std::vector<float> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, end - start);
    try {
      std::size_t pos = 0;
      const float v = std::stof(item, &pos);
      if (pos != item.size() || !std::isfinite(v) || std::abs(v) > kMaxOptionMagnitude)
        throw std::invalid_argument(item);
      out.push_back(v);
    } catch (const std::exception&) {
      throw Error(option, fmt::format("expects {} comma-separated finite numbers within +-{}, "
                                      "got '{}'",
                                      count, kMaxOptionMagnitude, echo(text)));
    }
    start = end + 1;
  }
  if (int(out.size()) != count)
    throw Error(option,
                fmt::format("expects {} comma-separated numbers, got '{}'", count, echo(text)));
  return out;
}

void parse_size(const std::string& option, const std::string& text, int& width, int& height) {
  const std::size_t x = text.find('x');
  try {
    if (x == std::string::npos) throw std::invalid_argument(text);
    std::size_t p1 = 0, p2 = 0;
    width = std::stoi(text.substr(0, x), &p1);
    height = std::stoi(text.substr(x + 1), &p2);
    if (p1 != x || p2 != text.size() - x - 1) throw std::invalid_argument(text);
  } catch (const std::exception&) {
    throw Error(option, fmt::format("expects WIDTHxHEIGHT, e.g. 1280x720, got '{}'", echo(text)));
  }
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    throw Error(option,
                fmt::format("width and height must be in [1, 16384], got '{}'", echo(text)));
  check_pixel_budget(option, width, height);
}

namespace {

// A shot file whose name starts with '-' ("-x.toml") would read as an option: an argument that
// ends in ".toml" and is no option of the command is taken as a file ("./-x.toml"), so it needs
// no "--" before it.
Args shot_files_as_paths(const CLI::App& app, Args args) {
  for (std::string& a : args) {
    if (a == "--") break;
    if (a.size() < 2 || a[0] != '-' || !a.ends_with(".toml")) continue;
    const std::string name =
        a[1] == '-' ? a.substr(0, a.find('=')) : a.substr(0, 2);  // "--opt=v" / "-xVALUE"
    if (!app.get_option_no_throw(name)) a = "./" + a;
  }
  return args;
}

}  // namespace

bool parse_cli(CLI::App& app, const Args& in) {
  const Args args = shot_files_as_paths(app, in);
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them reversed
  try {
    app.parse(reversed);
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    return true;
  } catch (const CLI::ParseError& e) {
    std::string message = e.what();
    std::replace(message.begin(), message.end(), '\n', ' ');
    throw Error("", message + " (see --help)");
  }
  return false;
}

void StagingOptions::add_to(CLI::App& app) {
  const SubjectTraits& t = traits(subject);
  const bool scene = subject == StagingSubject::kScene;
  app.add_option("--size", size, t.size_help)->capture_default_str();
  app.add_option("--aa", aa, "supersampling: N x N samples per pixel, [1, 4]")
      ->check(CLI::Range(1, 4))
      ->capture_default_str();
  app.add_option("--outline-width", outline_width, t.outline_width_help)
      ->check(CLI::Range(0.0f, 16.0f))
      ->capture_default_str();
  if (scene) {
    app.add_option("--crease", crease_deg,
                   "angle between face normals drawn as a crease line, degrees, [0, 180]")
        ->check(CLI::Range(0.0f, 180.0f))
        ->capture_default_str();
    app.add_option("--camera", camera,
                   "camera position X,Y,Z (world); default: placed by --azimuth/--elevation/"
                   "--distance around the subject");
    app.add_option("--target", target,
                   "point the camera looks at X,Y,Z; default: the subject's centre");
    app.add_option("--azimuth", azimuth,
                   "automatic camera: degrees around +Y, 0 = from +Z, any value")
        ->capture_default_str();
  }
  app.add_option("--elevation", elevation, t.elevation_help)
      ->check(CLI::Range(-t.max_elevation, t.max_elevation))
      ->capture_default_str();
  if (scene)
    app.add_option("--distance", distance,
                   "automatic camera: distance to the target, >= 0; 0 = fit the subject")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
  app.add_option("--fov", fov, t.fov_help)
      ->check(CLI::Range(1.0f, t.max_fov))
      ->capture_default_str();
  if (scene) {
    app.add_option(
           "--ortho", ortho,
           "orthographic camera showing this many scene units vertically, >= 0; 0 = perspective")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    add_motion_options(app);
  }
  app.add_option("--light", light, t.light_help)->capture_default_str();
  if (scene)
    app.add_flag("--light-world", light_world, "--light is a world-space direction (+Y up)");
  app.add_option("--softness", softness, t.softness_help)
      ->check(CLI::Range(0.0f, 45.0f))
      ->capture_default_str();
  app.add_flag("--no-ground", no_ground, t.no_ground_help);
  if (scene) add_ground_placement_options(app);
  app.add_option("--ground-color", ground_color, "linear RGB albedo of the ground, each in [0, 1]")
      ->capture_default_str();
  app.add_option("--background", background, "linear RGB background colour (albedo pass)")
      ->capture_default_str();
  app.add_option("--threads", threads, "worker threads, >= 0; 0 = all cores")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
}

void StagingOptions::add_motion_options(CLI::App& app) {
  app.add_option("--orbit", orbit,
                 "camera turns this many degrees around the target over the frame range")
      ->capture_default_str();
  app.add_option(
         "--dolly", dolly,
         "camera distance to the target is multiplied by this at the last frame, [0.01, 100]")
      ->capture_default_str();
  app.add_option("--pan", pan, "camera and target move by X,Y,Z over the frame range");
  app.add_option("--gltf-camera", gltf_camera,
                 "use the glTF camera on this node index (animated with the clip)");
}

void StagingOptions::add_ground_placement_options(CLI::App& app) {
  app.add_option("--ground-size", ground_size,
                 "side of the square ground plane, scene units, >= 0; 0 = 6x the subject")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--ground-height", ground_height,
                 "y of the ground plane; default: under the lowest point of the subject");
}

void StagingOptions::resolve(scene::ShotSpec& shot, render::RenderOptions& options) const {
  CHECK(subject == StagingSubject::kScene);
  parse_size("--size", size, options.width, options.height);
  resolve_shot(shot, options);
}

void StagingOptions::resolve(exemplar::ReferenceSpec& spec, render::RenderOptions& options) const {
  CHECK(subject == StagingSubject::kReferenceSphere);
  scene::ShotSpec shot;
  resolve_shot(shot, options);
  spec.elevation_deg = shot.camera.elevation_deg;
  spec.fov_deg = shot.camera.fov_deg;
  spec.light = shot.light;
  spec.ground = shot.ground.enabled;
  spec.ground_color = shot.ground.color;
  spec.background = shot.background;
}

void StagingOptions::resolve_shot(scene::ShotSpec& shot, render::RenderOptions& options) const {
  const SubjectTraits& t = traits(subject);
  // Every float option, finite and in its documented range, before anything is loaded (those a
  // subject does not offer keep their valid defaults).
  check_number("--outline-width", outline_width, 0.0f, 16.0f);
  check_number("--crease", crease_deg, 0.0f, 180.0f);
  check_number("--azimuth", azimuth);
  check_number("--elevation", elevation, -t.max_elevation, t.max_elevation);
  check_number("--distance", distance, 0.0f);
  check_number("--fov", fov, 1.0f, t.max_fov);
  check_number("--ortho", ortho, 0.0f);
  check_number("--orbit", orbit);
  check_number("--dolly", dolly, 0.01f, 100.0f);
  check_number("--softness", softness, 0.0f, 45.0f);
  check_number("--ground-size", ground_size, 0.0f);
  options.aa = aa;
  options.outline_width = outline_width;
  options.crease_deg = crease_deg;
  auto vec3 = [](const std::string& opt, const std::string& text) {
    const std::vector<float> v = parse_floats(opt, text, 3);
    return glm::vec3(v[0], v[1], v[2]);
  };
  scene::CameraSpec& cam = shot.camera;
  cam.azimuth_deg = azimuth;
  cam.elevation_deg = elevation;
  cam.distance = distance;
  cam.fov_deg = fov;
  cam.orthographic = ortho > 0.0f;
  cam.ortho_height = ortho;
  if (!target.empty()) cam.target = vec3("--target", target), cam.has_target = true;
  if (!camera.empty()) {
    cam.mode = scene::CameraSpec::Mode::kLookAt;
    cam.position = vec3("--camera", camera);
    if (!cam.has_target) throw Error("--camera", "needs --target as well");
  }
  cam.orbit_deg = orbit;
  cam.dolly = dolly;
  if (!pan.empty()) cam.pan = vec3("--pan", pan);
  if (gltf_camera >= 0) {
    cam.mode = scene::CameraSpec::Mode::kGltf;
    cam.gltf_node = gltf_camera;
  }
  shot.light.direction = vec3("--light", light);
  if (glm::length(shot.light.direction) == 0.0f) throw Error("--light", "must not be 0,0,0");
  shot.light.camera_relative = !light_world;
  shot.light.softness_deg = softness;
  shot.ground.enabled = !no_ground;
  shot.ground.size = ground_size;
  if (!ground_height.empty()) {
    shot.ground.height = parse_floats("--ground-height", ground_height, 1)[0];
    shot.ground.auto_height = false;
  }
  shot.ground.color = vec3("--ground-color", ground_color);
  shot.background = vec3("--background", background);
}

void make_output_dir(const std::string& option, const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw Error(option, fmt::format("cannot create folder '{}'", dir.string()));
}

void write_frame(const Image<float>& frame, const std::filesystem::path& exr,
                 const std::filesystem::path& preview_dir, const std::string& stem, bool half) {
  io::WriteOptions wo;
  wo.format = half ? io::SampleFormat::kHalf : io::SampleFormat::kFloat;
  wo.channel_names = render::channel_names();
  io::write_image(exr.string(), frame.cview(), wo);
  if (preview_dir.empty()) return;
  for (const render::PassInfo& pass : render::pass_table()) {
    const Image<float> p = render::preview(frame.cview(), pass);
    io::WriteOptions po;
    po.format = io::SampleFormat::kU8;
    io::write_image((preview_dir / fmt::format("{}_{}.png", stem, pass.name)).string(), p.cview(),
                    po);
  }
}

}  // namespace emaki::app
