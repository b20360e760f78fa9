// End-to-end tests of `emaki synth`: EbSynth's command line, bad input (one-line error naming
// the file or option, non-zero exit, no output file left behind), determinism across threads.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "core/rng.h"
#include "io/image_io.h"
#include "tests/cli_run.h"

namespace fs = std::filesystem;
using namespace emaki;

namespace {

struct RunResult {
  int exit_code;
  std::string err;
};

RunResult run(const std::string& args) {
  std::vector<std::string> argv = test::split_args(args);
  argv.insert(argv.begin(), "synth");
  const test::CliResult r = test::run_cli(EMAKI_BINARY, argv);
  return {r.exit_code, r.err};
}

using test::count_lines;

class SynthCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("emaki_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    write("style.png", 48, 40, 3, 1);
    write("src.png", 48, 40, 1, 2);
    write("tgt.png", 56, 44, 1, 3);
    write("src2.png", 48, 40, 3, 4);
    write("tgt2.png", 56, 44, 3, 5);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string p(const std::string& name) const { return (dir_ / name).string(); }

  void write(const std::string& name, int w, int h, int c, uint64_t seed, bool exr = false) {
    Image<float> im(w, h, c);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int k = 0; k < c; ++k) {
          CounterRng rng(hash_key(seed, y * 1000 + x, k));
          im(x, y, k) = 0.5f * rng.uniform_float() + 0.5f * float(x + y) / float(w + h);
        }
    io::WriteOptions o;
    if (exr)
      o.format = io::SampleFormat::kFloat;
    else
      o.format = io::SampleFormat::kU8;
    io::write_image(p(name), im.cview(), o);
  }

  std::string basic() const {
    return "-style " + p("style.png") + " -guide " + p("src.png") + " " + p("tgt.png") +
           " -weight 2 -guide " + p("src2.png") + " " + p("tgt2.png");
  }

  // Expects a failure whose single line names `subject`, and no file at `out`.
  void expect_error(const std::string& args, const std::string& subject, const std::string& out) {
    const RunResult r = run(args);
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(subject), std::string::npos) << "'" << subject << "' not in: " << r.err;
    EXPECT_FALSE(fs::exists(out)) << out;
    for (const auto& e : fs::directory_iterator(dir_))
      EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  }

  fs::path dir_;
};

TEST_F(SynthCli, EbSynthCommandLineWritesOutput) {
  const RunResult r = run(basic() + " -output " + p("out.png") +
                          " -uniformity 3500 -patchsize 5 -pyramidlevels 3 -searchvoteiters 2 "
                          "-patchmatchiters 2 -stopthreshold 5 -extrapass3x3 -backend cpu");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::AnyImage out = io::read_image(p("out.png"));
  EXPECT_EQ(out.width(), 56);
  EXPECT_EQ(out.height(), 44);
  EXPECT_EQ(out.channels(), 3);
}

TEST_F(SynthCli, SameOutputForOneAndTwoThreadsAndExtrasWritten) {
  ASSERT_EQ(run(basic() + " -output " + p("a.png") + " --threads 1 --nnf-out " + p("nnf.exr") +
                " --error-out " + p("err.exr"))
                .exit_code,
            0);
  ASSERT_EQ(run(basic() + " -output " + p("b.png") + " --threads 2").exit_code, 0);
  std::ifstream a(p("a.png"), std::ios::binary), b(p("b.png"), std::ios::binary);
  std::stringstream sa, sb;
  sa << a.rdbuf();
  sb << b.rdbuf();
  EXPECT_EQ(sa.str(), sb.str());
  const io::AnyImage nnf = io::read_image(p("nnf.exr"));
  EXPECT_EQ(nnf.channels(), 2);
  EXPECT_EQ(io::read_image(p("err.exr")).channels(), 1);
}

TEST_F(SynthCli, GrayGuideBesideColourGuide) {
  // src.png is one channel, tgt2.png three: the gray side is spread over RGB (EbSynth reads
  // every file as RGBA, so such pairs work there too).
  const RunResult r = run("-style " + p("style.png") + " -guide " + p("src.png") + " " +
                          p("tgt2.png") + " -output " + p("o.png"));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(p("o.png")));
}

TEST_F(SynthCli, MaskGivesAlpha) {
  Image<float> m(56, 44, 1);
  for (int y = 10; y < 30; ++y)
    for (int x = 10; x < 40; ++x) m(x, y) = 1.0f;
  io::write_image(p("mask.png"), m.cview());
  ASSERT_EQ(run(basic() + " -output " + p("o.png") + " --mask " + p("mask.png")).exit_code, 0);
  const io::AnyImage o = io::read_image(p("o.png"));
  ASSERT_EQ(o.channels(), 4);
  EXPECT_EQ(o.value(0, 0, 3), 0.0f);
  EXPECT_EQ(o.value(20, 20, 3), 1.0f);
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A white weight map is a weight of 1 everywhere: the same bytes as no map. A black one on the
// first guide drops it, which changes the output.
TEST_F(SynthCli, GuideWeightMap) {
  Image<float> white(56, 44, 1), black(56, 44, 1);
  white.fill(1.0f);
  io::write_image(p("white.png"), white.cview());
  io::write_image(p("black.png"), black.cview());
  ASSERT_EQ(run(basic() + " -output " + p("plain.png")).exit_code, 0);
  const RunResult r =
      run(basic() + " -output " + p("white_out.png") + " --guide-weight-map 1 " + p("white.png"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_EQ(
      run(basic() + " -output " + p("black_out.png") + " --guide-weight-map 1 " + p("black.png"))
          .exit_code,
      0);
  EXPECT_EQ(file_bytes(p("plain.png")), file_bytes(p("white_out.png")));
  EXPECT_NE(file_bytes(p("plain.png")), file_bytes(p("black_out.png")));
  expect_error(basic() + " -output " + p("o.png") + " --guide-weight-map 2 " + p("style.png"),
               "style.png", p("o.png"));  // 48x40, the output is 56x44
}

TEST_F(SynthCli, HelpDocumentsEveryOption) {
  const std::string cmd = std::string(EMAKI_BINARY) + " synth --help";
  FILE* f = popen(cmd.c_str(), "r");
  std::string text;
  char buf[4096];
  while (std::size_t n = fread(buf, 1, sizeof buf, f)) text.append(buf, n);
  EXPECT_EQ(pclose(f), 0);
  for (const char* opt :
       {"-style", "-guide", "-weight", "-output", "-uniformity", "-patchsize", "-pyramidlevels",
        "-searchvoteiters", "-patchmatchiters", "-extrapass3x3", "-backend", "--seed", "--threads",
        "--mask", "--guide-weight-map", "--nnf-out", "--error-out", "Default"})
    EXPECT_NE(text.find(opt), std::string::npos) << opt;
}

TEST_F(SynthCli, MissingFile) {
  expect_error("-style " + p("nope.png") + " -guide " + p("src.png") + " " + p("tgt.png") +
                   " -output " + p("o.png"),
               "nope.png", p("o.png"));
}

TEST_F(SynthCli, CorruptPng) {
  std::ofstream(p("bad.png"), std::ios::binary) << "\x89PNG\r\n\x1a\n garbage that is not a png";
  expect_error("-style " + p("style.png") + " -guide " + p("bad.png") + " " + p("tgt.png") +
                   " -output " + p("o.png"),
               "bad.png", p("o.png"));
}

TEST_F(SynthCli, SourceGuideSizeDiffersFromStyle) {
  expect_error("-style " + p("style.png") + " -guide " + p("tgt.png") + " " + p("tgt.png") +
                   " -output " + p("o.png"),
               "tgt.png", p("o.png"));
}

TEST_F(SynthCli, SourceGuideSizeErrorNamesTheSourceFile) {
  // synth::validate checks the sizes; the CLI gives it both file names.
  const RunResult r = run("-style " + p("style.png") + " -guide " + p("tgt2.png") + " " +
                          p("tgt.png") + " -output " + p("o.png"));
  EXPECT_EQ(r.err.rfind("emaki synth: error: " + p("tgt2.png") +
                            ": source guide is 56x44 but "
                            "the style '" +
                            p("style.png") + "' is 48x40",
                        0),
            0u)
      << r.err;
}

TEST_F(SynthCli, GuideFileOverFourChannelsIsNamed) {
  write("tgt5.exr", 56, 44, 5, 6, true);
  expect_error("-style " + p("style.png") + " -guide " + p("src.png") + " " + p("tgt5.exr") +
                   " -output " + p("o.png"),
               "tgt5.exr: a guide must have 1 to 4 channels", p("o.png"));
}

TEST_F(SynthCli, TargetGuidesOfDifferentSizes) {
  write("tgt_small.png", 50, 44, 1, 9);
  expect_error("-style " + p("style.png") + " -guide " + p("src.png") + " " + p("tgt.png") +
                   " -guide " + p("src2.png") + " " + p("tgt_small.png") + " -output " + p("o.png"),
               "tgt_small.png", p("o.png"));
}

TEST_F(SynthCli, GuideWithOnePath) {
  expect_error(
      "-style " + p("style.png") + " -guide " + p("src.png") + " -weight 0.5 -output " + p("o.png"),
      "-guide", p("o.png"));
}

TEST_F(SynthCli, EvenPatchSize) {
  expect_error(basic() + " -patchsize 4 -output " + p("o.png"), "-patchsize", p("o.png"));
}

TEST_F(SynthCli, PatchSizeBelowThree) {
  expect_error(basic() + " -patchsize 1 -output " + p("o.png"), "-patchsize", p("o.png"));
}

TEST_F(SynthCli, ImageSmallerThanPatch) {
  write("tiny_style.png", 4, 4, 3, 1);
  write("tiny_src.png", 4, 4, 1, 1);
  expect_error("-style " + p("tiny_style.png") + " -guide " + p("tiny_src.png") + " " +
                   p("tgt.png") + " -output " + p("o.png"),
               "tiny_style.png", p("o.png"));
}

TEST_F(SynthCli, NanInExrGuide) {
  Image<float> im(56, 44, 1);
  im(7, 9) = std::numeric_limits<float>::quiet_NaN();
  io::WriteOptions o;
  o.format = io::SampleFormat::kFloat;
  io::write_image(p("nan.exr"), im.cview(), o);
  write("src_f.exr", 48, 40, 1, 2, true);
  expect_error("-style " + p("style.png") + " -guide " + p("src_f.exr") + " " + p("nan.exr") +
                   " -output " + p("o.png"),
               "nan.exr", p("o.png"));
}

TEST_F(SynthCli, UnknownOption) {
  expect_error(basic() + " -output " + p("o.png") + " -frobnicate 3", "-frobnicate", p("o.png"));
}

TEST_F(SynthCli, UnwritableOutputPath) {
  const std::string out = p("no_such_folder") + "/o.png";
  expect_error(basic() + " -output " + out, "no_such_folder", out);
}

TEST_F(SynthCli, ReadOnlyFolder) {
  if (::geteuid() == 0) GTEST_SKIP() << "root can write anywhere";
  fs::create_directories(p("ro"));
  fs::permissions(p("ro"), fs::perms::owner_read | fs::perms::owner_exec);
  expect_error(basic() + " -output " + p("ro") + "/o.png", "ro/o.png", p("ro") + "/o.png");
}

}  // namespace
