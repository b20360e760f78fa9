// Colour management: OpenColorIO behind one small API. Everything above the engine names its
// colour spaces through it (paintings, paper, studio passes, previews); the engine (synth) sees
// numbers only and never meets a colour space.
//
// The config is, in this order: $OCIO when set and not empty, the shot file's `colour.config`,
// or emaki's own (src/colour/emaki.ocio, made by tools/colour/make_config.py and built into the
// binary): scene-linear Rec.709 (the reference), ACEScg, sRGB texture, raw, and an sRGB display
// with a Standard and a Filmic view.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/image.h"

namespace emaki::colour {

// The built-in config's names (docs and defaults name these; another config may lack them, so
// defaults go through the roles below: a name given in the shot file is checked against the
// config in use).
inline constexpr const char* kSceneLinear = "scene-linear Rec.709";
inline constexpr const char* kAcescg = "ACEScg";
inline constexpr const char* kSrgbTexture = "sRGB texture";
inline constexpr const char* kRaw = "raw";

class Config {
 public:
  // $OCIO when set, else `shot_config` (a path; empty: none), else the built-in config. An
  // unreadable or broken config is an emaki::Error naming $OCIO or `key`.
  static std::shared_ptr<const Config> open(const std::string& shot_config, const std::string& key);
  static std::shared_ptr<const Config> builtin();
  // `subject` names the file in errors (a key, "$OCIO", or the path itself).
  static std::shared_ptr<const Config> from_file(const std::string& path,
                                                 const std::string& subject);

  ~Config();
  Config(const Config&) = delete;
  Config& operator=(const Config&) = delete;

  // "the built-in config", "$OCIO (PATH)" or PATH: what errors say the names were looked up in.
  const std::string& origin() const;
  std::vector<std::string> space_names() const;  // colour spaces and roles
  // The colour space `name` stands for (a role resolved; "" when the config has no such name).
  std::string resolve(std::string_view name) const;
  // Throws emaki::Error(key, "unknown colour space 'X' in ORIGIN; nearest: 'a', 'b', 'c'").
  void require_space(const std::string& key, const std::string& name) const;
  // The display (empty: the config's default) and its view (empty: the display's default),
  // each named in errors by its key; returns {display, view} resolved.
  std::pair<std::string, std::string> require_display_view(const std::string& display_key,
                                                           const std::string& display,
                                                           const std::string& view_key,
                                                           const std::string& view) const;
  // The colour space a role names ("scene_linear", "color_picking", "data"); "" when absent.
  std::string role(std::string_view role) const;
  bool is_data(const std::string& space) const;
  // The colour space a display's view writes ("" for a view transform's display space).
  std::string view_space(const std::string& display, const std::string& view) const;

  // The chromaticities of `space`'s RGB (red, green, blue, white x y), as OpenEXR's attribute
  // holds them: its primaries and white converted to CIE XYZ through the config's
  // aces_interchange role and OpenColorIO's ACES AP0 -> XYZ (D65, Bradford) transform, so a
  // Rec.709-based space gives Rec.709 / D65 exactly. Empty when the config has no such role or
  // the space is data.
  std::vector<float> chromaticities(const std::string& space) const;

  // True when converting `src` to `dst` changes nothing: the same space, or either one data.
  bool is_identity(const std::string& src, const std::string& dst) const;
  // The first three channels of `image` converted from `src` to `dst`, in place (other
  // channels, alpha among them, are left as they are). Nothing is done when is_identity().
  void convert(ImageView<float> image, const std::string& src, const std::string& dst) const;
  // The same through a display and view (`src` scene-referred or display-referred alike).
  void to_display(ImageView<float> image, const std::string& src, const std::string& display,
                  const std::string& view) const;

 private:
  struct Impl;
  explicit Config(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The names of `candidates` nearest to `name` (edit distance, case folded), at most `count`.
std::vector<std::string> nearest_names(std::string_view name,
                                       const std::vector<std::string>& candidates,
                                       std::size_t count = 3);

}  // namespace emaki::colour
