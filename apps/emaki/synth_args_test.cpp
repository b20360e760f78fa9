// `emaki synth`'s parser alone (no files).
#include "apps/emaki/synth_args.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "apps/emaki/index_cache.h"
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

TEST(SynthArgs, IndexSetsTheCoherenceSetSize) {
  const std::vector<std::string> base{"-style", "s.png", "-guide", "a.png", "b.png"};
  auto with = [&](const std::string& v) {
    std::vector<std::string> a = base;
    a.insert(a.end(), {"--index", v});
    return a;
  };
  EXPECT_EQ(parse_synth_args(base).params.index_k, 0);
  EXPECT_EQ(parse_synth_args(with("4")).params.index_k, 4);
  EXPECT_NE(error_of(with("17")).find("--index"), std::string::npos);
  EXPECT_NE(error_of(with("-1")).find("--index"), std::string::npos);
}

TEST(IndexCache, StoresLoadsAndRejectsADamagedFile) {
  const std::string dir = ::testing::TempDir() + "emaki_index_cache_test";
  std::filesystem::remove_all(dir);
  SynthArgs a = parse_synth_args(
      {"-style", "s.png", "-guide", "a.png", "b.png", "--index", "2", "--index-cache", dir});
  const std::string path = index_cache_path(a);
  EXPECT_EQ(path.rfind(dir, 0), 0u);
  a.params.index_k = 3;
  EXPECT_NE(index_cache_path(a), path);               // k is part of the name
  EXPECT_EQ(load_cached_index(path, true), nullptr);  // no file yet
  synth::ExemplarIndex index;
  index.patch_size = 5, index.k = 2, index.features_digest = 42;
  index.levels.push_back({3, 2, 2, {-1, 0, 1, 2, 3, 4, 5, -1, -1, -1, 0, 1}});
  store_cached_index(path, index);
  const auto back = load_cached_index(path, true);
  ASSERT_NE(back, nullptr);
  EXPECT_EQ(back->features_digest, 42u);
  EXPECT_EQ(back->levels[0].entries, index.levels[0].entries);
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 1);
  EXPECT_EQ(load_cached_index(path, true), nullptr);
  EXPECT_NE(error_of({"-style", "s.png", "-guide", "a.png", "b.png", "--index-cache", dir})
                .find("--index-cache"),
            std::string::npos);
  std::filesystem::remove_all(dir);
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

}  // namespace
}  // namespace emaki::app
