// The colour module against OpenColorIO's own command-line tools (ocioconvert, ociocheck) as the
// reference, not against emaki's formulas.
#include "colour/colour.h"

#include <OpenColorIO/OpenColorIO.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include "colour/steps.h"
#include "core/error.h"
#include "core/parallel.h"
#include "io/image_io.h"

namespace emaki::colour {
namespace {

namespace fs = std::filesystem;

const std::string kBuiltinFile = std::string(EMAKI_SOURCE_DIR) + "/src/colour/emaki.ocio";
const std::string kBlenderConfig = "/usr/share/blender/datafiles/colormanagement/config.ocio";

// $OCIO unset for the test's duration (the reference tools read it too).
class ColourTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const char* v = std::getenv("OCIO")) saved_ = v;
    ::unsetenv("OCIO");
  }
  void TearDown() override {
    if (!saved_.empty()) ::setenv("OCIO", saved_.c_str(), 1);
  }
  std::string saved_;
};

// A patch of known colours: black, white, greys, primaries, a skin tone, out-of-range values.
Image<float> patch() {
  const float v[][3] = {{0, 0, 0},
                        {1, 1, 1},
                        {0.18f, 0.18f, 0.18f},
                        {0.5f, 0.5f, 0.5f},
                        {1, 0, 0},
                        {0, 1, 0},
                        {0, 0, 1},
                        {0.8f, 0.55f, 0.42f},
                        {0.02f, 0.3f, 0.9f},
                        {0.003f, 0.04f, 0.25f},
                        {0.95f, 0.9f, 0.1f},
                        {0.6f, 0.2f, 0.7f}};
  const int n = int(std::size(v));
  Image<float> img(n, 1, 3);
  for (int x = 0; x < n; ++x)
    for (int c = 0; c < 3; ++c) img(x, 0, c) = v[x][c];
  return img;
}

// The patch goes to ocioconvert as a PFM (plain floats) and comes back as a float EXR (OpenImageIO
// reads PFM but does not write it).
void write_pfm(const std::string& path, const Image<float>& img) {
  std::ofstream out(path, std::ios::binary);
  out << "PF\n" << img.width() << " " << img.height() << "\n-1.0\n";
  for (int y = img.height() - 1; y >= 0; --y)
    for (int x = 0; x < img.width(); ++x)
      for (int c = 0; c < 3; ++c) out.write(reinterpret_cast<const char*>(&img(x, y, c)), 4);
}

std::string temp_dir() {
  const fs::path d =
      fs::temp_directory_path() / ("emaki_colour_test_" + std::to_string(::getpid()) + "_" +
                                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::create_directories(d);
  return d.string();
}

// Runs `argv` with $OCIO = `config` (no shell: the arguments go to the program as they are);
// true when it exits 0. Its output is dropped.
bool run_tool(const std::string& config, const std::vector<std::string>& argv) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (config.empty())
      ::unsetenv("OCIO");
    else
      ::setenv("OCIO", config.c_str(), 1);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execvp(args[0], args.data());
    ::_exit(127);
  }
  int status = 0;
  return pid > 0 && ::waitpid(pid, &status, 0) == pid && WIFEXITED(status) &&
         WEXITSTATUS(status) == 0;
}

// OpenColorIO's own conversion of `in`: `ocioconvert IN SRC OUT DST`, or with `view` non-empty
// `ocioconvert --view IN SRC OUT DISPLAY VIEW`.
Image<float> ocioconvert(const std::string& config, const Image<float>& in, const std::string& src,
                         const std::string& dst, const std::string& view = "") {
  const std::string dir = temp_dir();
  const std::string a = dir + "/in.pfm", b = dir + "/out.exr";
  write_pfm(a, in);
  std::vector<std::string> argv = {"ocioconvert"};
  if (!view.empty()) argv.push_back("--view");
  for (const std::string& s : {a, src, b, dst}) argv.push_back(s);
  if (!view.empty()) argv.push_back(view);
  EXPECT_TRUE(run_tool(config, argv)) << "ocioconvert " << src << " -> " << dst << " " << view;
  Image<float> out = io::read_image_float(b);
  EXPECT_EQ(out.width(), in.width());
  fs::remove_all(dir);
  return out;
}

Image<float> copy_of(const Image<float>& img) {
  Image<float> out(img.width(), img.height(), img.channels());
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x)
      for (int c = 0; c < img.channels(); ++c) out(x, y, c) = img(x, y, c);
  return out;
}

void expect_near_image(const Image<float>& got, const Image<float>& want, float tolerance,
                       const std::string& what) {
  ASSERT_EQ(got.width(), want.width());
  for (int x = 0; x < got.width(); ++x)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(got(x, 0, c), want(x, 0, c), tolerance) << what << " pixel " << x << " c " << c;
}

// Debian's opencolorio-tools (their --help exits 1, so it cannot tell).
bool have_tools() {
  return fs::exists("/usr/bin/ocioconvert") && fs::exists("/usr/bin/ociocheck");
}

TEST_F(ColourTest, BuiltinConfigPassesOciocheck) {
  if (!have_tools()) GTEST_SKIP() << "opencolorio-tools not installed (scripts/setup.sh)";
  // ociocheck exits non-zero when the config fails validation.
  EXPECT_TRUE(run_tool("", {"ociocheck", "--iconfig", kBuiltinFile}));
  const std::string broken = temp_dir() + "/broken.ocio";
  std::ofstream(broken) << "ocio_profile_version: 2\nroles: {scene_linear: nowhere}\n";
  EXPECT_FALSE(run_tool("", {"ociocheck", "--iconfig", broken}));
  fs::remove_all(fs::path(broken).parent_path());
}

// The compiled-in text is the file in the repository.
TEST_F(ColourTest, BuiltinIsTheRepositoryFile) {
  const auto builtin = Config::builtin();
  const auto file = Config::from_file(kBuiltinFile, kBuiltinFile);
  EXPECT_EQ(builtin->space_names(), file->space_names());
  EXPECT_EQ(builtin->origin(), "the built-in config");
  EXPECT_EQ(builtin->role("scene_linear"), kSceneLinear);
  EXPECT_EQ(builtin->role("color_picking"), kSrgbTexture);
  EXPECT_TRUE(builtin->is_data(kRaw));
}

// Every input path (each space into the working spaces) and every output path (the working
// spaces out to each space and to the display's views), within 1e-4 of ocioconvert.
TEST_F(ColourTest, ConversionsMatchOcioconvert) {
  if (!have_tools()) GTEST_SKIP() << "opencolorio-tools not installed (scripts/setup.sh)";
  const auto config = Config::from_file(kBuiltinFile, kBuiltinFile);
  const std::string spaces[] = {kSceneLinear, kAcescg, kSrgbTexture};
  for (const std::string& src : spaces)
    for (const std::string& dst : spaces) {
      if (src == dst) continue;
      Image<float> got = patch();
      config->convert(got.view(), src, dst);
      expect_near_image(got, ocioconvert(kBuiltinFile, patch(), src, dst), 1e-4f,
                        src + " -> " + dst);
    }
  for (const std::string& src : {std::string(kSceneLinear), std::string(kSrgbTexture)})
    for (const std::string view : {"Standard", "Filmic"}) {
      Image<float> got = patch();
      config->to_display(got.view(), src, "sRGB", view);
      expect_near_image(got, ocioconvert(kBuiltinFile, patch(), src, "sRGB", view), 1e-4f,
                        src + " -> sRGB/" + view);
    }
}

// 8-bit: a display-referred value written as 8 bits is within 1 level of ocioconvert's.
TEST_F(ColourTest, EightBitWithinOneLevel) {
  if (!have_tools()) GTEST_SKIP() << "opencolorio-tools not installed (scripts/setup.sh)";
  const auto config = Config::builtin();
  Image<float> got = patch();
  config->convert(got.view(), kAcescg, kSrgbTexture);
  const Image<float> want = ocioconvert(kBuiltinFile, patch(), kAcescg, kSrgbTexture);
  for (int x = 0; x < got.width(); ++x)
    for (int c = 0; c < 3; ++c) {
      const auto level = [](float v) { return std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f); };
      EXPECT_LE(std::abs(level(got(x, 0, c)) - level(want(x, 0, c))), 1) << x << " " << c;
    }
}

// Alpha and any channel past the third are left as they are.
TEST_F(ColourTest, ConvertKeepsAlpha) {
  const auto config = Config::builtin();
  Image<float> img(2, 2, 4);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x)
      for (int c = 0; c < 4; ++c) img(x, y, c) = 0.25f * float(c) + 0.1f * float(x + y);
  const Image<float> before = copy_of(img);
  config->convert(img.view(), kSrgbTexture, kSceneLinear);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) {
      EXPECT_EQ(img(x, y, 3), before(x, y, 3));
      EXPECT_LT(img(x, y, 1), before(x, y, 1));  // sRGB decoding darkens mid values
    }
}

// Data and same-space conversions change nothing, bit for bit (the defaults keep today's bytes).
TEST_F(ColourTest, IdentityIsExact) {
  const auto config = Config::builtin();
  for (const auto& [src, dst] :
       {std::pair{kSrgbTexture, kSrgbTexture}, std::pair{kRaw, kSceneLinear},
        std::pair{kAcescg, kRaw}, std::pair{"color_picking", kSrgbTexture}}) {
    EXPECT_TRUE(config->is_identity(src, dst)) << src << " " << dst;
    Image<float> img = patch();
    config->convert(img.view(), src, dst);
    const Image<float> want = patch();
    for (int x = 0; x < img.width(); ++x)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(img(x, 0, c), want(x, 0, c));
  }
}

// OpenEXR's chromaticities: Rec.709 / D65 for the Rec.709-based spaces, ACEScg's AP1 primaries
// as seen from D65, none for data.
TEST_F(ColourTest, Chromaticities) {
  const auto config = Config::builtin();
  const std::vector<float> rec709 = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
  for (const char* space : {kSceneLinear, kSrgbTexture, "color_picking"}) {
    const std::vector<float> c = config->chromaticities(space);
    ASSERT_EQ(c.size(), 8u) << space;
    for (int i = 0; i < 8; ++i) EXPECT_NEAR(c[i], rec709[i], 1e-4) << space << " " << i;
  }
  const std::vector<float> ap1 = config->chromaticities(kAcescg);
  ASSERT_EQ(ap1.size(), 8u);
  EXPECT_NEAR(ap1[0], 0.713f, 2e-3);
  EXPECT_NEAR(ap1[3], 0.839f, 2e-3);  // AP1 green y (0.830 at D60), adapted to D65
  EXPECT_NEAR(ap1[6], 0.3127f, 1e-4);
  EXPECT_TRUE(config->chromaticities(kRaw).empty());
}

TEST_F(ColourTest, UnknownSpaceNamesKeyAndNearest) {
  const auto config = Config::builtin();
  try {
    config->require_space("exemplars.ink.colorspace", "sRGB textur");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), "exemplars.ink.colorspace");
    const std::string m = e.what();
    EXPECT_NE(m.find("unknown colour space 'sRGB textur' in the built-in config"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("nearest: 'sRGB texture'"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  EXPECT_NO_THROW(config->require_space("k", "ACEScg"));
  EXPECT_NO_THROW(config->require_space("k", "scene_linear"));  // a role
}

TEST_F(ColourTest, DisplayAndViewDefaultsAndErrors) {
  const auto config = Config::builtin();
  EXPECT_EQ(config->require_display_view("d", "", "v", ""),
            (std::pair<std::string, std::string>{"sRGB", "Standard"}));
  EXPECT_EQ(config->view_space("sRGB", "Standard"), kSrgbTexture);
  try {
    config->require_display_view("outputs.display", "sRGB", "outputs.view", "Filmc");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), "outputs.view");
    EXPECT_NE(std::string(e.what()).find("nearest: 'Filmic'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(config->require_display_view("outputs.display", "P3", "v", ""), Error);
}

TEST_F(ColourTest, BrokenConfigIsOneLineNamingTheKey) {
  const std::string dir = temp_dir();
  const std::string path = dir + "/broken.ocio";
  std::ofstream(path) << "ocio_profile_version: 2\nroles: {scene_linear: nowhere}\n";
  try {
    Config::open(path, "colour.config");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), "colour.config");
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
  EXPECT_THROW(Config::open(dir + "/missing.ocio", "colour.config"), Error);
  fs::remove_all(dir);
}

TEST_F(ColourTest, OcioEnvironmentWinsOverTheShotFile) {
  ::setenv("OCIO", kBuiltinFile.c_str(), 1);
  const auto config = Config::open("/nonexistent.ocio", "colour.config");
  EXPECT_EQ(config->origin(), "$OCIO (" + kBuiltinFile + ")");
  ::unsetenv("OCIO");
  EXPECT_EQ(Config::open("", "colour.config")->origin(), "the built-in config");
}

// Blender's config (Debian's blender package) works: its spaces convert as ocioconvert does.
TEST_F(ColourTest, BlenderConfig) {
  if (!fs::exists(kBlenderConfig))
    GTEST_SKIP() << kBlenderConfig << " is not installed (Debian's blender package): skipped";
  if (!have_tools()) GTEST_SKIP() << "opencolorio-tools not installed (scripts/setup.sh)";
  const auto config = Config::from_file(kBlenderConfig, kBlenderConfig);
  EXPECT_FALSE(config->role("scene_linear").empty());
  EXPECT_FALSE(config->role("color_picking").empty());
  EXPECT_TRUE(config->is_data("Non-Color"));
  const auto [display, view] = config->require_display_view("d", "", "v", "");
  for (const auto& [src, dst] : {std::pair{"sRGB", "Linear"}, std::pair{"Linear ACEScg", "Linear"},
                                 std::pair{"Linear", "sRGB"}}) {
    Image<float> got = patch();
    config->convert(got.view(), src, dst);
    expect_near_image(got, ocioconvert(kBlenderConfig, patch(), src, dst), 1e-4f,
                      std::string(src) + " -> " + dst);
  }
  Image<float> got = patch();
  config->to_display(got.view(), "Linear", display, "Filmic");
  expect_near_image(got, ocioconvert(kBlenderConfig, patch(), "Linear", display, "Filmic"), 1e-4f,
                    "Linear -> Filmic");
}

namespace OCIO = OCIO_NAMESPACE;

// Values a conversion meets and the ones it should survive: +-0, denormals, 2^-40 .. 2^40 at
// uneven steps (the tables' ends among them), every 8-bit level, 0 .. 1 finely, inf and NaN;
// then random RGB in [0, 1] and [-1, 64], one row per kind.
Image<float> sweep() {
  std::vector<float> v = {0.0f,
                          -0.0f,
                          1e-40f,
                          -1e-40f,
                          std::numeric_limits<float>::infinity(),
                          -std::numeric_limits<float>::infinity(),
                          std::numeric_limits<float>::quiet_NaN()};
  for (double e = -40.0; e < 40.0; e += 0.0137) {
    v.push_back(float(std::exp2(e)));
    v.push_back(-float(std::exp2(e)));
  }
  for (int i = 0; i <= 255; ++i) v.push_back(float(i) / 255.0f);
  for (int i = 0; i <= 20000; ++i) v.push_back(float(i) / 20000.0f);
  const int width = int(v.size());
  Image<float> img(width, 3, 3);
  uint64_t state = 0x9e3779b97f4a7c15ull;
  auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return float(state >> 40) / float(1 << 24);
  };
  for (int x = 0; x < width; ++x)
    for (int c = 0; c < 3; ++c) {
      img(x, 0, c) = v[std::size_t((x + c * 7919) % width)];
      img(x, 1, c) = next();
      img(x, 2, c) = next() * 65.0f - 1.0f;
    }
  return img;
}

// Steps (tables for the curves) against OpenColorIO's own processor, value by value: within
// 1e-5 (relative above 1; a tenth of what the tests against ocioconvert allow), inf and NaN where
// it gives them, for pixels that are finite; and `tables` tables are used (-1: any number).
void expect_steps_match(const OCIO::ConstConfigRcPtr& config,
                        const OCIO::ConstProcessorRcPtr& processor, int tables,
                        const std::string& what) {
  const Steps steps(config, processor);
  if (tables >= 0) {
    EXPECT_EQ(steps.table_steps(), tables) << what;
  }
  Image<float> got = sweep(), want = sweep();
  steps.apply(got.view());
  const ImageView<float> w = want.view();
  OCIO::PackedImageDesc desc(w.row(0), w.width, w.height, OCIO::CHANNEL_ORDERING_RGB,
                             OCIO::BIT_DEPTH_F32, sizeof(float), 3 * sizeof(float),
                             w.stride * std::ptrdiff_t(sizeof(float)));
  processor->getDefaultCPUProcessor()->apply(desc);
  const Image<float> in = sweep();
  int bad = 0;
  float worst = 0.0f;
  for (int y = 0; y < got.height(); ++y)
    for (int x = 0; x < got.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        // A pixel with inf or NaN in: what comes out depends on how OpenColorIO joins its ops.
        if (!(std::isfinite(in(x, y, 0)) && std::isfinite(in(x, y, 1)) &&
              std::isfinite(in(x, y, 2))))
          continue;
        const float g = got(x, y, c), w = want(x, y, c);
        const bool ok = std::isnan(w)   ? std::isnan(g)
                        : std::isinf(w) ? g == w
                                        : std::abs(g - w) <= 1e-5f * std::max(1.0f, std::abs(w));
        if (std::isfinite(w))
          worst = std::max(worst, std::abs(g - w) / std::max(1.0f, std::abs(w)));
        if (!ok && ++bad <= 5)
          ADD_FAILURE() << what << ": in " << in(x, y, c) << " got " << g << " want " << w;
      }
  EXPECT_EQ(bad, 0) << what;
  std::printf("%s: %d tables, %d processors, largest difference %.3g\n", what.c_str(),
              steps.table_steps(), steps.processor_steps(), double(worst));
  // Each pixel's result is its own: one pixel at a time, or on one thread, gives the same bits.
  Image<float> alone = sweep();
  for (int x = 0; x < alone.width(); x += 97) {
    ImageView<float> one = alone.view();
    one.data = alone.view().row(1) + std::ptrdiff_t(x) * 3;
    one.width = one.height = 1;
    steps.apply(one);
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(std::bit_cast<uint32_t>(alone(x, 1, c)), std::bit_cast<uint32_t>(got(x, 1, c)))
          << what << " pixel " << x;
  }
  const ScopedThreadCount one_thread(1);
  Image<float> serial = sweep();
  steps.apply(serial.view());
  for (int y = 0; y < got.height(); ++y)
    for (int x = 0; x < got.width(); ++x)
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(std::bit_cast<uint32_t>(serial(x, y, c)), std::bit_cast<uint32_t>(got(x, y, c)));
}

OCIO::ConstProcessorRcPtr view_processor(const OCIO::ConstConfigRcPtr& config, const char* src,
                                         const char* display, const char* view) {
  OCIO::DisplayViewTransformRcPtr t = OCIO::DisplayViewTransform::Create();
  t->setSrc(src);
  t->setDisplay(display);
  t->setView(view);
  return config->getProcessor(t);
}

TEST_F(ColourTest, StepsMatchTheProcessor) {
  const auto config = OCIO::Config::CreateFromFile(kBuiltinFile.c_str());
  expect_steps_match(config, config->getProcessor(kSrgbTexture, kSceneLinear), 1,
                     "sRGB texture -> scene-linear");
  expect_steps_match(config, config->getProcessor(kSceneLinear, kSrgbTexture), 1,
                     "scene-linear -> sRGB texture");
  expect_steps_match(config, config->getProcessor(kAcescg, kSceneLinear), 0,
                     "ACEScg -> scene-linear");
  expect_steps_match(config, config->getProcessor(kAcescg, kSrgbTexture), 1,
                     "ACEScg -> sRGB texture");
  expect_steps_match(config, view_processor(config, kSceneLinear, "sRGB", "Filmic"), 2,
                     "scene-linear -> Filmic");
  expect_steps_match(config, view_processor(config, kSrgbTexture, "sRGB", "Filmic"), 3,
                     "sRGB texture -> Filmic");
  if (!fs::exists(kBlenderConfig)) GTEST_SKIP() << kBlenderConfig << " is not installed";
  const auto blender = OCIO::Config::CreateFromFile(kBlenderConfig.c_str());
  // Blender 3.4's Standard view is a 1D LUT (no table), its Filmic a log curve before its LUTs
  // (one table); another Blender's config may cut otherwise.
  for (const char* view : {"Standard", "Filmic"}) {
    const auto p = view_processor(blender, "Linear", blender->getDefaultDisplay(), view);
    expect_steps_match(blender, p, -1, std::string("Blender Linear -> ") + view);
  }
}

}  // namespace
}  // namespace emaki::colour
