// emaki view's page in Debian's headless Chromium: the binary serves small output folders (the
// layout `emaki run` writes: composite/, layers/NAME/, QA maps under qa/KIND/LAYER/, manifests,
// contact sheet), Chromium loads the page at a frame and layer named in the URL's hash, and the
// DOM (frame number, layer and overlay names, manifest) and a screenshot (against the frame's own
// pixels, a QA map over it, and an A/B wipe) are checked.
// Skipped when chromium is not installed (scripts/setup.sh installs it).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/image.h"
#include "io/image_io.h"
#include "tests/small_painting.h"

namespace {

namespace fs = std::filesystem;

// The browser: EMAKI_CHROMIUM when set (a path that is not executable skips the tests),
// else Debian's.
const char* chromium() {
  const char* env = std::getenv("EMAKI_CHROMIUM");
  const char* path = env && *env ? env : "/usr/bin/chromium";
  return ::access(path, X_OK) == 0 ? path : nullptr;
}

// Frame `frame` of output `ab` (0: A, 1: B): flat quadrants whose colours depend on both, so a
// screenshot of one frame cannot match another.
emaki::Image<float> frame_image(int frame, int ab) {
  emaki::Image<float> img(64, 48, 3);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      const int q = (x >= 32) + 2 * (y >= 24);
      img(x, y, 0) = float((40 * q + 60 * frame) % 256) / 255.f;
      img(x, y, 1) = float(ab ? 200 : 30) / 255.f;
      img(x, y, 2) = float((255 - 50 * q - 30 * frame) % 256) / 255.f;
    }
  return img;
}

// A QA map as `emaki qa flicker --maps` writes it (store/qa_maps.h): a colour over the left half,
// black (nothing measured) over the right.
emaki::Image<float> map_image() {
  emaki::Image<float> img(64, 48, 3);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 32; ++x) img(x, y, 0) = 0.8f, img(x, y, 1) = 0.4f;
  return img;
}

void write_output(const fs::path& dir, int ab) {
  fs::create_directories(dir / "composite");
  for (const char* layer : {"base", "shadow"}) fs::create_directories(dir / "layers" / layer);
  for (int f = 0; f < 3; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.png", f);
    emaki::io::write_image((dir / "composite" / name).string(), frame_image(f, ab).cview());
    for (const char* layer : {"base", "shadow"}) {
      std::snprintf(name, sizeof name, "%s_%04d.png", layer, f);
      emaki::io::write_image((dir / "layers" / layer / name).string(),
                             frame_image(f + 5, ab).cview());
    }
  }
  for (const char* kind : {"flicker", "error"}) {
    fs::create_directories(dir / "qa" / kind / "base");
    for (int f = 1; f < 3; ++f) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%04d.png", f);
      emaki::io::write_image((dir / "qa" / kind / "base" / name).string(), map_image().cview());
    }
  }
  emaki::io::write_image((dir / "contact_sheet.png").string(), frame_image(0, ab).cview());
  std::ofstream(dir / "composite" / ".emaki-manifest")
      << "outputs_format = 1\nemaki_version = browser-test-" << ab << "\n";
}

class ViewBrowser : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!chromium()) GTEST_SKIP() << "chromium is not installed (scripts/setup.sh installs it)";
    base = fs::temp_directory_path() / ("emaki_view_browser_" + std::to_string(::getpid()));
    fs::remove_all(base);
    write_output(base / "a", 0);
    write_output(base / "b", 1);
  }
  void TearDown() override {
    stop();
    fs::remove_all(base);
  }

  // Stops the server serve() started.
  void stop() {
    if (pid <= 0) return;
    ::kill(pid, SIGTERM);
    int status = 0;
    ::waitpid(pid, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "emaki view did not stop";
    pid = -1;
    url.clear();
  }

  // Starts `emaki view` on the folders and reads the URL it prints.
  void serve(std::vector<std::string> folders) {
    int out[2];
    ASSERT_EQ(::pipe(out), 0);
    pid = ::fork();
    if (pid == 0) {
      ::dup2(out[1], 1);
      ::close(out[0]);
      std::vector<char*> argv{const_cast<char*>(EMAKI_BINARY), const_cast<char*>("view")};
      for (auto& f : folders) argv.push_back(f.data());
      argv.push_back(nullptr);
      ::execv(EMAKI_BINARY, argv.data());
      ::_exit(127);
    }
    ::close(out[1]);
    char c;
    while (::read(out[0], &c, 1) == 1 && c != '\n') url += c;
    ::close(out[0]);
    ASSERT_EQ(url.rfind("http://127.0.0.1:", 0), 0u) << url;
  }

  // Chromium's output for the page at `hash`: the DOM (--dump-dom) or a screenshot file.
  std::string browse(const std::string& hash, const std::string& mode,
                     const std::string& window = "200,150") {
    const fs::path profile = base / ("profile_" + std::to_string(++runs));
    const fs::path out = base / ("out_" + std::to_string(runs));
    // --no-sandbox: CI runs as root, where Chromium's sandbox refuses to start. The page polls
    // its listing once at load; 4 s of virtual time lets it fetch and draw.
    std::string command = std::string("timeout 120 ") + chromium() +
                          " --headless --no-sandbox --disable-gpu --hide-scrollbars"
                          " --force-device-scale-factor=1 --window-size=" +
                          window +
                          " --virtual-time-budget=4000 --user-data-dir=" + profile.string() + " " +
                          mode + " '" + url + "#" + hash + "' > " + out.string() + " 2>/dev/null";
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
    std::ifstream in(out);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }

  // The largest difference (in 1/255) between the screenshot's region at (x0, 0) and `expected`'s
  // columns [x0, x1).
  double screenshot_difference(const fs::path& shot, const emaki::Image<float>& expected, int x0,
                               int x1) {
    const emaki::io::AnyImage s = emaki::io::read_image(shot.string());
    double worst = 0;
    for (int y = 0; y < expected.height(); ++y)
      for (int x = x0; x < x1; ++x)
        for (int c = 0; c < 3; ++c)
          worst = std::max(worst, std::abs(double(s.value(x, y, c)) - expected(x, y, c)) * 255);
    return worst;
  }

  fs::path base;
  pid_t pid = -1;
  std::string url;
  int runs = 0;
};

TEST_F(ViewBrowser, DomShowsTheFrameTheLayersAndTheManifest) {
  serve({(base / "a").string()});
  const std::string dom = browse("frame=1&layer=layers/base", "--dump-dom");
  EXPECT_NE(dom.find("id=\"frame-number\">1<"), std::string::npos) << dom;
  for (const char* layer :
       {"composite", "layers/base", "layers/shadow", "qa/error/base", "qa/flicker/base"}) {
    EXPECT_NE(dom.find(std::string("data-layer=\"") + layer + "\""), std::string::npos) << layer;
    EXPECT_NE(dom.find(std::string("<option value=\"") + layer + "\""), std::string::npos)
        << layer << " is not among the overlays";
  }
  EXPECT_NE(dom.find("emaki_version = browser-test-0"), std::string::npos);
  EXPECT_NE(dom.find("(3 frames)"), std::string::npos);
  EXPECT_NE(dom.find("files/0/layers/base/base_0001.png"), std::string::npos);
}

TEST_F(ViewBrowser, TheHashStepsToAnotherFrame) {
  serve({(base / "a").string()});
  EXPECT_NE(browse("frame=2", "--dump-dom").find("id=\"frame-number\">2<"), std::string::npos);
  // A frame that does not exist lands on the nearest one.
  EXPECT_NE(browse("frame=9", "--dump-dom").find("id=\"frame-number\">2<"), std::string::npos);
}

TEST_F(ViewBrowser, TheScreenshotIsTheFramesPixels) {
  serve({(base / "a").string()});
  const fs::path shot = base / "frame2.png";
  browse("frame=2&layer=composite&bare=1", "--screenshot=" + shot.string());
  ASSERT_TRUE(fs::exists(shot));
  EXPECT_LE(screenshot_difference(shot, frame_image(2, 0), 0, 64), 2.0);
  EXPECT_GT(screenshot_difference(shot, frame_image(1, 0), 0, 64), 20.0);
}

// A QA map over the frame: screen-blended at 60 % where it has colour, the frame alone where
// it is black.
TEST_F(ViewBrowser, AQaMapIsDrawnOverTheFrame) {
  serve({(base / "a").string()});
  const fs::path shot = base / "overlay.png";
  browse("frame=1&layer=composite&overlay=qa/flicker/base&bare=1", "--screenshot=" + shot.string());
  ASSERT_TRUE(fs::exists(shot));
  const emaki::Image<float> frame = frame_image(1, 0), map = map_image();
  emaki::Image<float> blended = frame.clone();
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c) {
        const float a = frame(x, y, c), b = map(x, y, c);
        blended(x, y, c) = a + 0.6f * b * (1 - a);  // a + 0.6 (screen(a, b) - a)
      }
  EXPECT_LE(screenshot_difference(shot, blended, 0, 64), 3.0);
  EXPECT_GT(screenshot_difference(shot, frame, 0, 32), 20.0);
}

TEST_F(ViewBrowser, TheWipeShowsAOnTheLeftAndBOnTheRight) {
  serve({(base / "a").string(), (base / "b").string()});
  const std::string dom = browse("frame=1&compare=wipe&wipe=0.5", "--dump-dom");
  EXPECT_NE(dom.find("emaki_version = browser-test-1"), std::string::npos);
  const fs::path shot = base / "wipe.png";
  browse("frame=1&compare=wipe&wipe=0.5&bare=1", "--screenshot=" + shot.string());
  ASSERT_TRUE(fs::exists(shot));
  EXPECT_LE(screenshot_difference(shot, frame_image(1, 0), 0, 31), 2.0);
  EXPECT_LE(screenshot_difference(shot, frame_image(1, 1), 33, 64), 2.0);
}

// The guide's screenshots (docs/view.md), made from a real shot: the Fox at 384x216 run with
// the temporal chain (A, with its error and flicker maps) and frame by frame (B). They are
// written into the folder EMAKI_SCREENSHOTS names (docs/images to refresh the guide's), else
// into the test's scratch folder; each must be the page's size and show what it is about.
TEST_F(ViewBrowser, GuideScreenshots) {
  const std::string data = EMAKI_TEST_DATA;
  emaki::test::write_small_painting(data + "/stylit/source_style.png",
                                    (base / "pastel.png").string(), 300, 228);
  const auto shot = [&](const std::string& name, bool temporal) {
    std::ofstream(base / (name + ".toml"))
        << "[source]\nscene = \"" << data << "/scenes/Fox.glb\"\nclip = \"Walk\"\n"
        << "frames = [0, 2]\nsize = [384, 216]\naa = 1\n"
        << "[source.camera]\nazimuth = 35\nelevation = 14\n"
        << "[source.light]\ndirection = [0.3, 0.9, -0.3]\nsoftness = 8\n"
        << "[exemplars.pastel]\npainting = \"pastel.png\"\nsphere = [152.05, 123.55, 60.6]\n"
        << "elevation = 20\nfov = 30\nlight = [0.3, 0.9, -0.3]\nsoftness = 8\n"
        << "[layers.base]\nkind = \"base\"\nexemplar = \"pastel\"\n"
        << "guides = { normal = 1.0, diffuse = 1.5 }\n"
        << (temporal ? "" : "temporal = false\n")
        << "[layers.shadow]\nkind = \"shadow\"\nexemplar = \"pastel\"\n"
        << "color = [0.42, 0.40, 0.62]\nblend = \"multiply\"\nopacity = 0.8\n"
        << (temporal ? "" : "temporal = false\n")
        << "[layers.outline]\nkind = \"outline\"\nexemplar = \"pastel\"\n"
        << "color = [0.16, 0.09, 0.07]\n"
        << (temporal ? "" : "temporal = false\n") << "[compositing]\npaper = \"" << data
        << "/papers/roughpaper.png\"\n"
        << "paper_color = [1.0, 0.97, 0.9]\n[outputs]\nfolder = \"" << name << "\"\nmp4 = false\n";
  };
  shot("temporal", true);
  shot("frame_by_frame", false);
  const auto emaki = [&](const std::string& args) {
    const std::string command =
        "cd '" + base.string() + "' && " + EMAKI_BINARY + " " + args + " > /dev/null 2> emaki.log";
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
  };
  emaki("run temporal.toml --error-maps");
  emaki("qa flicker temporal.toml --layer base --maps");
  emaki("run frame_by_frame.toml");
  const char* env = std::getenv("EMAKI_SCREENSHOTS");
  const fs::path out = env && *env ? fs::path(env) : base;
  const auto screenshot = [&](const std::string& name, const std::string& hash) {
    const fs::path file = out / name;
    browse(hash, "--screenshot=" + file.string(), "760,362");
    const emaki::io::AnyImage s = emaki::io::read_image(file.string());
    EXPECT_EQ(s.width(), 760) << name;
    EXPECT_EQ(s.height(), 362) << name;
    return file;
  };
  serve({(base / "temporal").string()});
  const std::string dom = browse("frame=2&overlay=qa/error/base", "--dump-dom");
  for (const char* layer : {"layers/outline", "qa/error/base", "qa/flicker/base"})
    EXPECT_NE(dom.find(std::string("data-layer=\"") + layer + "\""), std::string::npos) << layer;
  const fs::path player = screenshot("view_player.png", "frame=2");
  const fs::path overlay = screenshot("view_error_overlay.png", "frame=2&overlay=qa/error/base");
  // The map over the frame changes it (the frame's top-left corner is at (10, 70) or below).
  const emaki::io::AnyImage a = emaki::io::read_image(player.string());
  const emaki::io::AnyImage b = emaki::io::read_image(overlay.string());
  double moved = 0;
  for (int y = 70; y < a.height(); ++y)
    for (int x = 10; x < 394; ++x)
      moved = std::max(moved, double(std::abs(a.value(x, y, 0) - b.value(x, y, 0))));
  EXPECT_GT(moved * 255, 20.0);
  stop();
  serve({(base / "temporal").string(), (base / "frame_by_frame").string()});
  screenshot("view_wipe.png", "frame=2&compare=wipe&wipe=0.5");
}

}  // namespace
