// EbSynth's channel rules over images in memory: channel counts, what is copied, error names.
#include "synth/ebsynth_rules.h"

#include <gtest/gtest.h>

#include <string>

#include "core/error.h"

namespace emaki::synth {
namespace {

Image<uint8_t> rgb(int w, int h, bool gray) {
  Image<uint8_t> im(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) im(x, y, c) = uint8_t(gray ? x * 9 + y : x * 9 + y + c * 40);
  return im;
}

Image<float> with_alpha(int w, int h, float alpha) {
  Image<float> im(w, h, 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) im(x, y, c) = 0.1f * float(c + x);
      im(x, y, 3) = alpha;
    }
  return im;
}

std::string error_of(const NamedPlane& style, const std::vector<NamedGuide>& guides) {
  try {
    apply_ebsynth_rules(style, guides, std::nullopt);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(EbsynthRules, EqualChannelRgbCountsAsOne) {
  EXPECT_EQ(effective_channels(rgb(5, 4, true).cview()), 1);
  EXPECT_EQ(effective_channels(rgb(5, 4, false).cview()), 3);
}

TEST(EbsynthRules, OpaqueAlphaIsDropped) {
  EXPECT_EQ(effective_channels(with_alpha(5, 4, 1.0f).cview()), 3);
  EXPECT_EQ(effective_channels(with_alpha(5, 4, 0.5f).cview()), 4);
}

TEST(EbsynthRules, ColourInputsGoToTheEngineUncopied) {
  const Image<uint8_t> style = rgb(8, 6, false), a = rgb(8, 6, false), b = rgb(10, 7, false);
  const RuledInputs r =
      apply_ebsynth_rules({style.cview(), "style"}, {{{a.cview(), "a"}, {b.cview(), "b"}}}, {});
  EXPECT_EQ(r.images_made(), 0);
  EXPECT_EQ(std::get<0>(r.inputs.style).data, style.cview().data);
  EXPECT_EQ(std::get<0>(r.inputs.guides[0].target).data, b.cview().data);
  EXPECT_EQ(r.inputs.guides[0].name, "b");
  EXPECT_EQ(r.inputs.guides[0].source_name, "a");
}

TEST(EbsynthRules, GrayIsSpreadOverRgbWhenItsPartnerIsInColour) {
  const Image<uint8_t> style = rgb(8, 6, false), colour = rgb(9, 5, false);
  Image<uint8_t> gray(8, 6, 1);
  gray(2, 3) = 77;
  RuledInputs r = apply_ebsynth_rules({style.cview(), "style"},
                                      {{{gray.cview(), "a"}, {colour.cview(), "b"}}}, {});
  const auto& src = std::get<0>(r.inputs.guides[0].source);
  ASSERT_EQ(src.channels, 3);
  EXPECT_EQ(r.images_made(), 1);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(src(2, 3, c), 77);
  r.release_guides();
  EXPECT_EQ(r.images_made(), 0);
  EXPECT_TRUE(r.inputs.guides.empty());
}

TEST(EbsynthRules, EqualChannelRgbStyleIsMadeOneChannel) {
  const Image<uint8_t> style = rgb(8, 6, true), a = rgb(8, 6, false), b = rgb(9, 5, false);
  const RuledInputs r =
      apply_ebsynth_rules({style.cview(), "style"}, {{{a.cview(), "a"}, {b.cview(), "b"}}}, {});
  EXPECT_EQ(r.images_made(), 1);
  EXPECT_EQ(plane_channels(r.inputs.style), 1);
}

TEST(EbsynthRules, ErrorsNameTheImage) {
  const Image<uint8_t> style = rgb(8, 6, false), small = rgb(7, 6, false), t1 = rgb(9, 5, false),
                       t2 = rgb(9, 6, false);
  EXPECT_EQ(error_of({style.cview(), "s"}, {{{small.cview(), "a"}, {t1.cview(), "b"}}})
                .rfind("a: source guide is 7x6 but the style 's' is 8x6", 0),
            0u);
  EXPECT_EQ(error_of({style.cview(), "s"}, {{{style.cview(), "a"}, {t1.cview(), "b"}},
                                            {{style.cview(), "c"}, {t2.cview(), "d"}}})
                .rfind("d: target guide is 9x6 but 'b' is 9x5", 0),
            0u);
  const Image<float> five(8, 6, 5);
  EXPECT_EQ(error_of({five.cview(), "s"}, {}).rfind("s: style must have 1 to 4 channels", 0), 0u);
}

TEST(EbsynthRules, GrayResultComesBackAsRgb) {
  Image<float> g(3, 2, 2);
  g(1, 1, 0) = 0.25f;
  g(1, 1, 1) = 0.5f;
  const Image<float> out = gray_to_rgb(g);
  ASSERT_EQ(out.channels(), 4);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(out(1, 1, c), 0.25f);
  EXPECT_EQ(out(1, 1, 3), 0.5f);
}

}  // namespace
}  // namespace emaki::synth
