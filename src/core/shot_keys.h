// The shot file's spelling of every key that code outside src/shot names (in errors, and in the
// synthesizer's guide names, which its errors quote), and of the neutral fields (Error::Field)
// src/shot re-spells as keys. The one place a key is spelled outside the schema
// (shot/schema.cpp, which gives each key's type, default and range; shot/schema_test checks
// every key here is in it).
//
// It lives in core, not in src/shot, because the code that names these keys sits below
// src/shot: composite (which depends on core alone), pipeline, store and farm. src/shot depends
// on all of them; were the table in src/shot they would climb back up to it. core is the one
// module under every one of them.
#pragma once

#include <string>
#include <string_view>

namespace emaki::shot_keys {

// "layers.NAME"
inline std::string layer(std::string_view name) {
  return "layers." + std::string(name);
}
// "layers.NAME.KEY"
inline std::string layer_key(std::string_view name, std::string_view key) {
  return layer(name) + "." + std::string(key);
}
// "layers.NAME.guides.PASS"
inline std::string layer_guide(std::string_view name, std::string_view pass) {
  return layer_key(name, "guides") + "." + std::string(pass);
}
// "exemplars.NAME.KEY"
inline std::string exemplar_key(std::string_view name, std::string_view key) {
  return "exemplars." + std::string(name) + "." + std::string(key);
}

// Layer keys named outside src/shot.
inline constexpr std::string_view kSingleColour = "single_colour";
inline constexpr std::string_view kTemporal = "temporal";
inline constexpr std::string_view kColor = "color";
inline constexpr std::string_view kGradient = "gradient";
// Exemplar keys named outside src/shot.
inline constexpr std::string_view kPainting = "painting";
inline constexpr std::string_view kColorspace = "colorspace";

// Colour management (colour/colour.h): the config and the colour spaces, displays and views
// named in it.
inline constexpr const char* kColourConfig = "colour.config";
inline constexpr const char* kPassesColorspace = "source.passes_colorspace";
inline constexpr const char* kPaperColorspace = "compositing.paper_colorspace";
inline constexpr const char* kCompositingSpace = "compositing.space";
inline constexpr const char* kOutputsDisplay = "outputs.display";
inline constexpr const char* kOutputsView = "outputs.view";

inline constexpr const char* kPaperScale = "compositing.paper_scale";
inline constexpr const char* kOutputsFolder = "outputs.folder";
inline constexpr const char* kOutputsMp4 = "outputs.mp4";

// The key of each neutral field (Error::Field) the shot's loaders can meet. `section` is the
// table the field sits in; an exemplar's key takes its name ("exemplars.NAME.sphere").
struct FieldKey {
  const char* field;
  const char* section;
  const char* key;
};
inline constexpr FieldKey kFieldKeys[] = {
    {"frames", "source", "frames"},
    {"sequence", "source", "sequence"},
    {"fps", "source", "fps"},
    {"clip", "source", "clip"},
    {"start", "source", "start"},
    {"aa", "source", "aa"},
    {"gltf_node", "source", "camera.gltf_node"},
    {"sphere", "exemplars", "sphere"},
    {"horizon", "exemplars", "horizon"},
};

}  // namespace emaki::shot_keys
