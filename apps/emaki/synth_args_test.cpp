// `emaki synth`'s parser alone (no files) and EbSynth's channel rules.
#include "apps/emaki/synth_args.h"

#include <gtest/gtest.h>

#include <array>
#include <string>

#include "core/error.h"

namespace emaki::app {
namespace {

std::string error_of(const std::vector<std::string>& args) {
  try {
    parse_synth_args(args);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(SynthArgs, EbSynthCommandLine) {
  const SynthArgs a =
      parse_synth_args({"-style", "s.png", "-weight", "2", "-guide", "a.png", "b.png", "-weight",
                        "0.5", "-guide", "c.png", "d.png", "-output", "o.png", "-patchsize", "7",
                        "-uniformity", "1000", "-extrapass3x3"});
  EXPECT_EQ(a.style_path, "s.png");
  EXPECT_EQ(a.style_weight, 2.0f);
  ASSERT_EQ(a.guides.size(), 2u);
  EXPECT_EQ(a.guides[0].weight, 0.5f);
  EXPECT_EQ(a.guides[1].weight, -1.0f);
  EXPECT_EQ(a.guides[1].target, "d.png");
  EXPECT_EQ(a.output, "o.png");
  EXPECT_EQ(a.params.patch_size, 7);
  EXPECT_EQ(a.params.uniformity, 1000.0f);
  EXPECT_TRUE(a.params.extra_pass_3x3);
}

TEST(SynthArgs, ErrorsNameTheOption) {
  const std::vector<std::string> base{"-style", "s.png", "-guide", "a.png", "b.png"};
  struct Case {
    std::vector<std::string> extra;
    std::string starts;
  } cases[] = {
      {{"-patchsize", "4"}, "-patchsize: must be odd"},
      {{"-patchsize", "2147483647"}, "-patchsize: must be <= 65"},
      {{"-patchsize", "99999999999999"}, "-patchsize: expects an integer"},
      {{"-searchvoteiters", "2000000000"}, "-searchvoteiters: must be in [0, 1000]"},
      {{"-patchmatchiters", "-1"}, "-patchmatchiters: must be in [0, 1000]"},
      {{"-pyramidlevels", "33"}, "-pyramidlevels: must be in [1, 32]"},
      {{"--threads", "100000"}, "--threads: must be in [0, 1024]"},
      {{"-uniformity", "nan"}, "-uniformity: expects a number"},
      {{"-weight", "inf"}, "-weight: expects a number"},
      {{"-weight", "1e30"}, "-weight: must be <= 1e6"},
      {{"--vote", "x"}, "--vote: must be plain or weighted"},
      {{"-output"}, "-output: is missing its value"},
      {{"--bogus"}, "--bogus: unknown option"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = base;
    args.insert(args.end(), c.extra.begin(), c.extra.end());
    EXPECT_EQ(error_of(args).rfind(c.starts, 0), 0u) << c.starts << " vs " << error_of(args);
  }
  EXPECT_EQ(error_of({"-guide", "a.png", "b.png"}).rfind("-style: is required", 0), 0u);
  EXPECT_EQ(error_of({"-style", "s.png"}).rfind("-guide: at least one", 0), 0u);
}

TEST(SynthArgs, GuideWeightMapsNameTheirGuide) {
  const SynthArgs a = parse_synth_args({"--guide-weight-map", "2", "m.png", "-style", "s.png",
                                        "-guide", "a.png", "b.png", "-guide", "c.png", "d.png"});
  ASSERT_EQ(a.guides.size(), 2u);
  EXPECT_EQ(a.guides[0].weight_map, "");
  EXPECT_EQ(a.guides[1].weight_map, "m.png");
  const std::vector<std::string> base{"-style", "s.png", "-guide", "a.png", "b.png"};
  struct Case {
    std::vector<std::string> extra;
    std::string starts;
  } cases[] = {
      {{"--guide-weight-map", "2", "m.png"}, "--guide-weight-map: guide 2 does not exist"},
      {{"--guide-weight-map", "0", "m.png"}, "--guide-weight-map: must be in [1, 64]"},
      {{"--guide-weight-map", "1"}, "--guide-weight-map: needs a guide number and a file"},
      {{"--guide-weight-map", "1", "m.png", "--guide-weight-map", "1", "n.png"},
       "--guide-weight-map: guide 1 has two weight maps"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = base;
    args.insert(args.end(), c.extra.begin(), c.extra.end());
    EXPECT_EQ(error_of(args).rfind(c.starts, 0), 0u) << c.starts << " vs " << error_of(args);
  }
}

TEST(SynthArgs, EchoedValuesAreCapped) {
  const std::string huge(1 << 20, 'x');
  const std::string e = error_of({"-style", "s.png", "-guide", "a", "b", "-patchsize", huge});
  EXPECT_LT(e.size(), 200u) << e.size();
  EXPECT_LT(error_of({huge}).size(), 200u);
}

TEST(SynthArgs, TooManyGuides) {
  std::vector<std::string> args{"-style", "s.png"};
  for (int i = 0; i <= kMaxGuides; ++i) args.insert(args.end(), {"-guide", "a.png", "b.png"});
  EXPECT_EQ(error_of(args).rfind("-guide: at most", 0), 0u);
}

io::AnyImage rgb(int w, int h, bool gray) {
  Image<uint8_t> im(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) im(x, y, c) = uint8_t(gray ? x * 9 + y : x * 9 + y + c * 40);
  io::AnyImage a;
  a.image = std::move(im);
  return a;
}

TEST(SynthArgs, EqualChannelRgbCountsAsOne) {
  EXPECT_EQ(effective_channels(rgb(5, 4, true)), 1);
  EXPECT_EQ(effective_channels(rgb(5, 4, false)), 3);
}

TEST(SynthArgs, GrayIsSpreadOverRgb) {
  io::AnyImage g = with_channels(rgb(5, 4, true), 1);
  ASSERT_EQ(g.channels(), 1);
  const io::AnyImage back = with_channels(std::move(g), 3);
  ASSERT_EQ(back.channels(), 3);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(back.value(2, 3, c), back.value(2, 3, 0));
}

io::AnyImage rgba(int w, int h, bool gray, uint8_t alpha) {
  const io::AnyImage colour = rgb(w, h, gray);
  Image<uint8_t> im(w, h, 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) im(x, y, c) = uint8_t(colour.value(x, y, c) * 255.0f + 0.5f);
      im(x, y, 3) = x == 0 ? alpha : 255;
    }
  io::AnyImage a;
  a.image = std::move(im);
  return a;
}

TEST(SynthArgs, OpaqueAlphaIsDropped) {
  EXPECT_EQ(effective_channels(rgba(5, 4, false, 255)), 3);
  EXPECT_EQ(effective_channels(rgba(5, 4, true, 255)), 1);
  EXPECT_EQ(effective_channels(rgba(5, 4, true, 254)), 4);
  Image<float> gray_alpha(3, 2, 2);
  gray_alpha.fill(1.0f);
  io::AnyImage a;
  a.image = std::move(gray_alpha);
  EXPECT_EQ(effective_channels(a), 1);
}

SynthArgs three_guides() {
  return parse_synth_args({"-style", "s.png", "-guide", "a.png", "b.png", "-guide", "c.png",
                           "d.png", "-weight", "0", "-guide", "e.png", "f.png", "-weight", "2.5"});
}

TEST(SynthChannels, DefaultWeightsAreEbSynths) {
  const SynthChannels c = resolve_channels(three_guides(), 3, {{1, 1}, {3, 3}, {1, 1}});
  EXPECT_EQ(c.style_weight, 1.0f);
  ASSERT_EQ(c.guides.size(), 3u);
  EXPECT_EQ(c.guides[0].weight, 1.0f / 3.0f);  // no -weight: 1 / number of guides
  EXPECT_EQ(c.guides[1].weight, 0.0f);         // an explicit 0 is kept
  EXPECT_EQ(c.guides[2].weight, 2.5f);
}

TEST(SynthChannels, StyleWeightFollowsTheStyle) {
  const SynthArgs a = parse_synth_args({"-style", "s.png", "-weight", "4", "-guide", "a", "b"});
  EXPECT_EQ(resolve_channels(a, 1, {{1, 1}}).style_weight, 4.0f);
}

TEST(SynthChannels, PairTakesTheLargerCount) {
  const SynthChannels c = resolve_channels(three_guides(), 1, {{1, 3}, {4, 2}, {2, 2}});
  EXPECT_EQ(c.style_channels, 1);
  EXPECT_EQ(c.guides[0].channels, 3);
  EXPECT_EQ(c.guides[1].channels, 4);
  EXPECT_EQ(c.guides[2].channels, 2);
}

TEST(SynthChannels, StyleCountIsLeftToTheEngine) {
  // synth::validate names the style file for a count outside 1 to 4; the rules pass it on.
  EXPECT_EQ(resolve_channels(three_guides(), 5, {{1, 1}, {1, 1}, {1, 1}}).style_channels, 5);
}

TEST(SynthChannels, GuideOverFourChannelsNamesTheFile) {
  auto error = [](std::array<int, 2> second) {
    try {
      resolve_channels(three_guides(), 3, {{1, 1}, second, {1, 1}});
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error({5, 1}), "c.png: a guide must have 1 to 4 channels (has 5)");
  EXPECT_EQ(error({3, 6}), "d.png: a guide must have 1 to 4 channels (has 6)");
  EXPECT_EQ(error({5, 6}), "c.png: a guide must have 1 to 4 channels (has 5)");
  EXPECT_EQ(error({4, 4}), "");
}

TEST(SynthChannels, GrayFileBesideColourFile) {
  // An equal-channel RGB source counts as gray; beside a colour target the pair is RGB.
  const SynthArgs a = parse_synth_args({"-style", "s.png", "-guide", "a", "b"});
  const SynthChannels c = resolve_channels(
      a, 3, {{effective_channels(rgb(5, 4, true)), effective_channels(rgb(5, 4, false))}});
  EXPECT_EQ(c.guides[0].channels, 3);
}

}  // namespace
}  // namespace emaki::app
