#include "store/kept_fields.h"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>

namespace emaki::io {
namespace {

pipeline::KeptField field(int w, int h, uint64_t seed) {
  pipeline::KeptField k;
  k.guide = pipeline::AdvectionGuide::kPosition;
  k.patch_size = k.field.patch_size = 5;
  k.seed = seed;
  k.field.nnf.reset(w, h, 2);
  k.field.error.reset(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      k.field.nnf(x, y, 0) = (x + int(seed)) % w;
      k.field.nnf(x, y, 1) = (y * 3) % h;
      k.field.error(x, y) = float(x * 7 + y) / 3.0f;
    }
  return k;
}

std::vector<pipeline::KeptField> just(pipeline::KeptField k) {
  std::vector<pipeline::KeptField> v;
  v.push_back(std::move(k));
  return v;
}

// `k` with a visible map and the shares of two ids, as a field made with surfaces has.
pipeline::KeptField with_surfaces(pipeline::KeptField k) {
  const int w = k.field.nnf.width(), h = k.field.nnf.height();
  k.field.visible.reset(w, h, 1);
  k.field.shares.radius = 2;
  k.field.shares.ids = {0.0f, 3.0f};
  for (int i = 0; i < 2; ++i) {
    Image<float> share(w, h, 1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        k.field.visible(x, y) = uint8_t((x + y) % 2);
        share(x, y) = float((x + i) % 3) / 2.0f;
      }
    k.field.shares.share.push_back(std::move(share));
  }
  return k;
}

bool same(const pipeline::KeptField& a, const pipeline::KeptField& b) {
  if (a.guide != b.guide || a.patch_size != b.patch_size || a.seed != b.seed ||
      a.field.patch_size != b.field.patch_size || a.field.shares.radius != b.field.shares.radius ||
      a.field.shares.ids != b.field.shares.ids ||
      a.field.visible.empty() != b.field.visible.empty())
    return false;
  for (std::size_t i = 0; i < a.field.shares.share.size(); ++i)
    for (int y = 0; y < a.field.nnf.height(); ++y)
      for (int x = 0; x < a.field.nnf.width(); ++x)
        if (a.field.shares.share[i](x, y) != b.field.shares.share[i](x, y)) return false;
  for (int y = 0; y < a.field.visible.height(); ++y)
    for (int x = 0; x < a.field.visible.width(); ++x)
      if (a.field.visible(x, y) != b.field.visible(x, y)) return false;
  for (int y = 0; y < a.field.nnf.height(); ++y)
    for (int x = 0; x < a.field.nnf.width(); ++x)
      if (a.field.nnf(x, y, 0) != b.field.nnf(x, y, 0) ||
          a.field.nnf(x, y, 1) != b.field.nnf(x, y, 1) ||
          a.field.error(x, y) != b.field.error(x, y))
        return false;
  return true;
}

TEST(KeptFields, ReadBackAsWritten) {
  std::vector<pipeline::KeptField> in;
  in.push_back(field(13, 7, 1));
  in.push_back(with_surfaces(field(13, 7, 99)));
  in[1].guide = pipeline::AdvectionGuide::kRestPosition;
  const std::string bytes = encode_kept_fields(4, 13, 7, in);
  const std::vector<pipeline::KeptField> out =
      decode_kept_fields(bytes.data(), bytes.size(), 4, 13, 7);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_TRUE(same(in[0], out[0]));
  EXPECT_TRUE(same(in[1], out[1]));
  EXPECT_TRUE(out[0].field.visible.empty());
  EXPECT_TRUE(out[0].field.shares.empty());
  EXPECT_FALSE(out[1].field.visible.empty());
  EXPECT_EQ(out[1].field.shares.share.size(), 2u);
}

TEST(KeptFields, AnotherFrameOrSizeGivesNone) {
  const std::string bytes = encode_kept_fields(4, 13, 7, just(field(13, 7, 1)));
  EXPECT_TRUE(decode_kept_fields(bytes.data(), bytes.size(), 5, 13, 7).empty());
  EXPECT_TRUE(decode_kept_fields(bytes.data(), bytes.size(), 4, 7, 13).empty());
  EXPECT_EQ(decode_kept_fields(bytes.data(), bytes.size(), 4, 13, 7).size(), 1u);
}

TEST(KeptFields, AFileCutShortOrLongerGivesNone) {
  const std::string bytes = encode_kept_fields(0, 13, 7, just(field(13, 7, 1)));
  for (std::size_t n : {std::size_t(0), std::size_t(39), std::size_t(40), bytes.size() - 4})
    EXPECT_TRUE(decode_kept_fields(bytes.data(), n, 0, 13, 7).empty()) << n;
  const std::string longer = bytes + std::string(4, '\0');
  EXPECT_TRUE(decode_kept_fields(longer.data(), longer.size(), 0, 13, 7).empty());
}

TEST(KeptFields, AChangedByteGivesNone) {
  const std::string bytes = encode_kept_fields(0, 13, 7, just(with_surfaces(field(13, 7, 1))));
  for (std::size_t at : {std::size_t(20), std::size_t(45), std::size_t(100), bytes.size() - 1}) {
    std::string b = bytes;
    b[at] = char(b[at] ^ 0x10);
    EXPECT_TRUE(decode_kept_fields(b.data(), b.size(), 0, 13, 7).empty()) << at;
  }
}

TEST(KeptFields, SealingWritesTheDigestEncodingWrites) {
  const std::string bytes = encode_kept_fields(0, 13, 7, just(with_surfaces(field(13, 7, 1))));
  std::string b = bytes;
  for (std::size_t at = 32; at < 40; ++at) b[at] = char(b[at] ^ 0x5a);  // the digest
  EXPECT_TRUE(decode_kept_fields(b.data(), b.size(), 0, 13, 7).empty());
  seal_kept_fields(b.data(), b.size());
  EXPECT_EQ(b, bytes);
  EXPECT_EQ(decode_kept_fields(b.data(), b.size(), 0, 13, 7).size(), 1u);
}

// A file whose digest matches but whose entries leave the frame, or whose errors or shares are
// not finite, is not a field emaki made: nothing is taken from it.
TEST(KeptFields, EntriesOutsideTheFrameOrNonFiniteErrorsGiveNone) {
  pipeline::KeptField outside = field(13, 7, 1);
  outside.field.nnf(3, 2, 0) = 13;
  std::string b = encode_kept_fields(0, 13, 7, just(std::move(outside)));
  EXPECT_TRUE(decode_kept_fields(b.data(), b.size(), 0, 13, 7).empty());
  pipeline::KeptField negative = field(13, 7, 1);
  negative.field.nnf(0, 6, 1) = -1;
  b = encode_kept_fields(0, 13, 7, just(std::move(negative)));
  EXPECT_TRUE(decode_kept_fields(b.data(), b.size(), 0, 13, 7).empty());
  pipeline::KeptField nan = field(13, 7, 1);
  nan.field.error(12, 6) = std::numeric_limits<float>::quiet_NaN();
  b = encode_kept_fields(0, 13, 7, just(std::move(nan)));
  EXPECT_TRUE(decode_kept_fields(b.data(), b.size(), 0, 13, 7).empty());
  pipeline::KeptField share = with_surfaces(field(13, 7, 1));
  share.field.shares.share[1](4, 4) = std::numeric_limits<float>::infinity();
  b = encode_kept_fields(0, 13, 7, just(std::move(share)));
  EXPECT_TRUE(decode_kept_fields(b.data(), b.size(), 0, 13, 7).empty());
}

}  // namespace
}  // namespace emaki::io
