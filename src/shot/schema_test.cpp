#include "shot/schema.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "core/error.h"
#include "core/shot_keys.h"
#include "shot/parser.h"

namespace emaki::shot {
namespace {

const std::string kDocs = std::string(EMAKI_SOURCE_DIR) + "/docs/shot_file.md";
constexpr const char* kBegin = "<!-- schema table: made from src/shot/schema.cpp -->\n";
constexpr const char* kEnd = "<!-- end of schema table -->\n";

// docs/shot_file.md's key table is the schema's. EMAKI_UPDATE_DOCS=1 rewrites it.
TEST(Schema, DocsTableIsTheSchema) {
  std::ifstream in(kDocs);
  ASSERT_TRUE(in) << kDocs;
  std::stringstream ss;
  ss << in.rdbuf();
  std::string doc = ss.str();
  const std::size_t b = doc.find(kBegin), e = doc.find(kEnd);
  ASSERT_NE(b, std::string::npos) << "no schema table marker in " << kDocs;
  ASSERT_NE(e, std::string::npos) << "no end marker in " << kDocs;
  const std::size_t from = b + std::string(kBegin).size();
  const std::string table = doc.substr(from, e - from);
  if (std::getenv("EMAKI_UPDATE_DOCS")) {
    doc.replace(from, e - from, schema_markdown());
    std::ofstream(kDocs) << doc;
    GTEST_SKIP() << "rewrote " << kDocs;
  }
  EXPECT_EQ(table, schema_markdown())
      << "docs/shot_file.md is out of date: run EMAKI_UPDATE_DOCS=1 build/release/src/shot/"
         "schema_test";
}

TEST(Schema, KeysAreUniqueAndUnderTheirTables) {
  std::set<std::string_view> seen;
  for (const KeySpec& k : schema()) {
    EXPECT_TRUE(seen.insert(k.key).second) << k.key;
    EXPECT_FALSE(k.meaning.empty()) << k.key;
    EXPECT_EQ(std::isnan(k.lo), std::isnan(k.hi)) << k.key;
    if (!std::isnan(k.lo)) {
      EXPECT_LE(k.lo, k.hi) << k.key;
    }
  }
  EXPECT_EQ(child_keys(""),
            (std::vector<std::string>{"threads", "limits", "colour", "source", "exemplars",
                                      "layers", "compositing", "outputs"}));
  EXPECT_EQ(child_keys("source.light"),
            (std::vector<std::string>{"direction", "world", "softness", "turn"}));
  EXPECT_NE(find_key("layers.NAME.guides.PASS"), nullptr);
  EXPECT_EQ(find_key("layers.NAME.wieght"), nullptr);
}

// The keys code below src/shot spells (core/shot_keys.h) are the schema's.
TEST(Schema, KeysSpelledOutsideTheShotModuleAreInIt) {
  using namespace shot_keys;
  for (const std::string& key :
       {layer("NAME"), layer_key("NAME", kSingleColour), layer_key("NAME", kTemporal),
        layer_key("NAME", kColor), layer_key("NAME", kGradient), layer_guide("NAME", "PASS"),
        exemplar_key("NAME", kPainting), exemplar_key("NAME", kColorspace),
        std::string(kPaperScale), std::string(kOutputsFolder), std::string(kOutputsMp4),
        std::string(kColourConfig), std::string(kPassesColorspace), std::string(kPaperColorspace),
        std::string(kCompositingSpace), std::string(kOutputsDisplay), std::string(kOutputsView)})
    EXPECT_NE(find_key(key), nullptr) << key;
  for (const FieldKey& k : kFieldKeys) {
    const std::string section = k.section;
    const std::string key =
        section == "exemplars" ? exemplar_key("NAME", k.key) : section + "." + k.key;
    EXPECT_NE(find_key(key), nullptr) << k.field << " -> " << key;
  }
}

std::string error_of(const std::string& layer_line) {
  const std::string data = EMAKI_TEST_DATA;
  const std::string text = "[source]\nscene = \"" + data +
                           "/scenes/Fox.glb\"\nframes = [0, 3]\nsize = [64, 48]\n"
                           "[exemplars.sphere]\npainting = \"" +
                           data + "/stylit/source_style.png\"\n[layers.base]\nkind = \"base\"\n" +
                           "exemplar = \"sphere\"\n" + layer_line +
                           "\n[outputs]\nfolder = \"/tmp/emaki_schema_test_out\"\n";
  try {
    parse_shot(text, "/tmp/shot.toml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// A matcap exemplar without `elevation` gets the reference camera's one default, the value the
// table (and so the docs) shows; python/tests/test_defaults.py holds the other front ends to it.
TEST(Schema, ExemplarElevationDefaultIsTheReferenceCamerasDefault) {
  const std::string data = EMAKI_TEST_DATA;
  const std::string text =
      "[source]\nscene = \"" + data +
      "/scenes/Fox.glb\"\nframes = [0, 3]\nsize = [64, 48]\n"
      "[exemplars.sphere]\npainting = \"" +
      data + "/stylit/source_style.png\"\n[layers.base]\nkind = \"base\"\n" +
      "exemplar = \"sphere\"\n[outputs]\nfolder = \"/tmp/emaki_schema_test_out\"\n";
  const pipeline::Shot shot = parse_shot(text, "/tmp/shot.toml");
  ASSERT_EQ(shot.exemplars.size(), 1u);
  EXPECT_EQ(shot.exemplars[0].reference.elevation_deg, exemplar::kDefaultReferenceElevationDeg);
  const KeySpec* key = find_key("exemplars.NAME.elevation");
  ASSERT_TRUE(key);
  std::ostringstream shown;
  shown << "`" << exemplar::kDefaultReferenceElevationDeg << "`";
  EXPECT_EQ(key->default_value, shown.str());
}

// The parser's ranges are the table's: a value just outside each layer number's range is an
// error naming the key and the range the docs show.
TEST(Schema, ParserChecksTheTablesRanges) {
  const std::string prefix = "layers.NAME.";
  int checked = 0;
  for (const KeySpec& k : schema()) {
    const std::string_view key = k.key;
    if (key.substr(0, prefix.size()) != prefix || std::isnan(k.hi)) continue;
    const std::string name(key.substr(prefix.size()));
    if (name.find('.') != std::string::npos) continue;
    const bool integer = k.type == "integer";
    const std::string over =
        integer ? std::to_string(int64_t(k.hi) + 1) : std::to_string(k.hi * 1.5 + 1);
    const std::string err = error_of(name + " = " + over);
    EXPECT_EQ(err.rfind("layers.base." + name + ": must be in [", 0), 0u) << name << ": " << err;
    ++checked;
  }
  EXPECT_GE(checked, 10);
}

}  // namespace
}  // namespace emaki::shot
