#include "colour/colour.h"

#include <OpenColorIO/OpenColorIO.h>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <functional>
#include <map>
#include <mutex>
#include <sstream>

#include "colour/steps.h"
#include "core/error.h"

namespace emaki::colour {

namespace OCIO = OCIO_NAMESPACE;

// The text of src/colour/emaki.ocio, compiled in (builtin_config.cpp, made by CMake).
extern const char* const kBuiltinConfigText;

struct Config::Impl {
  OCIO::ConstConfigRcPtr config;
  std::string origin;
  // Processors by (src, dst) or (src, display, view): OCIO caches them too, but finding one
  // there takes a lock and a digest of the config per call.
  mutable std::mutex mutex;
  mutable std::map<std::string, OCIO::ConstCPUProcessorRcPtr> processors;
  // The conversions of images (convert, to_display), run as steps (colour/steps.h).
  mutable std::map<std::string, std::shared_ptr<const Steps>> conversions;

  // `cache`'s entry under `key`, made by `make` the first time (an OCIO failure to make it is an
  // error naming `what`).
  template <typename V>
  V cached(std::map<std::string, V>& cache, const std::string& key, const std::function<V()>& make,
           const std::string& what) const {
    const std::lock_guard<std::mutex> lock(mutex);
    auto it = cache.find(key);
    if (it != cache.end()) return it->second;
    try {
      return cache[key] = make();
    } catch (const OCIO::Exception& e) {
      throw Error(origin, fmt::format("cannot convert {}: {}", what, e.what()));
    }
  }

  OCIO::ConstCPUProcessorRcPtr processor(const std::string& cache_key,
                                         const std::function<OCIO::ConstProcessorRcPtr()>& make,
                                         const std::string& what) const {
    return cached<OCIO::ConstCPUProcessorRcPtr>(
        processors, cache_key, [&] { return make()->getDefaultCPUProcessor(); }, what);
  }

  std::shared_ptr<const Steps> conversion(const std::string& cache_key,
                                          const std::function<OCIO::ConstProcessorRcPtr()>& make,
                                          const std::string& what) const {
    return cached<std::shared_ptr<const Steps>>(
        conversions, cache_key, [&] { return std::make_shared<const Steps>(config, make()); },
        what);
  }
};

namespace {

std::string folded(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = char(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

int edit_distance(std::string_view a, std::string_view b) {
  std::vector<int> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = int(j);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    int diagonal = row[0];
    row[0] = int(i);
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const int up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string quoted_list(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "'" : ", '") + n + "'";
  return out;
}

}  // namespace

std::vector<std::string> nearest_names(std::string_view name,
                                       const std::vector<std::string>& candidates,
                                       std::size_t count) {
  std::vector<std::pair<int, std::string>> scored;
  const std::string want = folded(name);
  for (const std::string& c : candidates) scored.emplace_back(edit_distance(want, folded(c)), c);
  std::stable_sort(scored.begin(), scored.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::string> out;
  for (std::size_t i = 0; i < scored.size() && i < count; ++i) out.push_back(scored[i].second);
  return out;
}

Config::Config(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Config::~Config() = default;

std::shared_ptr<const Config> Config::builtin() {
  static const std::shared_ptr<const Config> config = [] {
    auto impl = std::make_unique<Impl>();
    std::istringstream text(kBuiltinConfigText);
    impl->config = OCIO::Config::CreateFromStream(text);
    impl->origin = "the built-in config";
    return std::shared_ptr<const Config>(new Config(std::move(impl)));
  }();
  return config;
}

std::shared_ptr<const Config> Config::from_file(const std::string& path,
                                                const std::string& subject) {
  auto impl = std::make_unique<Impl>();
  try {
    impl->config = OCIO::Config::CreateFromFile(path.c_str());
    impl->config->validate();
  } catch (const OCIO::Exception& e) {
    std::string message = e.what();
    std::replace(message.begin(), message.end(), '\n', ' ');
    throw Error(subject, fmt::format("cannot use the OpenColorIO config '{}': {}", path, message));
  }
  impl->origin = subject == path ? path : fmt::format("{} ({})", subject, path);
  return std::shared_ptr<const Config>(new Config(std::move(impl)));
}

std::shared_ptr<const Config> Config::open(const std::string& shot_config, const std::string& key) {
  if (const char* env = std::getenv("OCIO"); env && *env) return from_file(env, "$OCIO");
  if (!shot_config.empty()) return from_file(shot_config, key);
  return builtin();
}

const std::string& Config::origin() const {
  return impl_->origin;
}

std::vector<std::string> Config::space_names() const {
  const OCIO::ConstConfigRcPtr& c = impl_->config;
  std::vector<std::string> out;
  const int n = c->getNumColorSpaces(OCIO::SEARCH_REFERENCE_SPACE_ALL, OCIO::COLORSPACE_ALL);
  for (int i = 0; i < n; ++i)
    out.emplace_back(
        c->getColorSpaceNameByIndex(OCIO::SEARCH_REFERENCE_SPACE_ALL, OCIO::COLORSPACE_ALL, i));
  for (int i = 0; i < c->getNumRoles(); ++i) out.emplace_back(c->getRoleName(i));
  return out;
}

std::string Config::resolve(std::string_view name) const {
  const OCIO::ConstColorSpaceRcPtr cs = impl_->config->getColorSpace(std::string(name).c_str());
  return cs ? cs->getName() : "";
}

void Config::require_space(const std::string& key, const std::string& name) const {
  if (!resolve(name).empty()) return;
  throw Error(key, fmt::format("unknown colour space '{}' in {}; nearest: {}", name, impl_->origin,
                               quoted_list(nearest_names(name, space_names()))));
}

std::pair<std::string, std::string> Config::require_display_view(const std::string& display_key,
                                                                 const std::string& display,
                                                                 const std::string& view_key,
                                                                 const std::string& view) const {
  const OCIO::ConstConfigRcPtr& c = impl_->config;
  std::vector<std::string> displays;
  for (int i = 0; i < c->getNumDisplays(); ++i) displays.emplace_back(c->getDisplay(i));
  const std::string d = display.empty() ? c->getDefaultDisplay() : display;
  if (std::find(displays.begin(), displays.end(), d) == displays.end())
    throw Error(display_key, fmt::format("unknown display '{}' in {}; nearest: {}", d,
                                         impl_->origin, quoted_list(nearest_names(d, displays))));
  std::vector<std::string> views;
  for (int i = 0; i < c->getNumViews(d.c_str()); ++i) views.emplace_back(c->getView(d.c_str(), i));
  const std::string v = view.empty() ? c->getDefaultView(d.c_str()) : view;
  if (std::find(views.begin(), views.end(), v) == views.end())
    throw Error(view_key, fmt::format("unknown view '{}' of display '{}' in {}; nearest: {}", v, d,
                                      impl_->origin, quoted_list(nearest_names(v, views))));
  return {d, v};
}

std::string Config::role(std::string_view role) const {
  const std::string r(role);
  return impl_->config->hasRole(r.c_str()) ? resolve(r) : "";
}

bool Config::is_data(const std::string& space) const {
  const OCIO::ConstColorSpaceRcPtr cs = impl_->config->getColorSpace(space.c_str());
  return cs && cs->isData();
}

std::string Config::view_space(const std::string& display, const std::string& view) const {
  const char* name = impl_->config->getDisplayViewColorSpaceName(display.c_str(), view.c_str());
  return name ? resolve(name) : "";
}

std::vector<float> Config::chromaticities(const std::string& space) const {
  if (role("aces_interchange").empty() || resolve(space).empty() || is_data(space)) return {};
  const auto cpu = impl_->processor(
      space + "\nchromaticities",
      [&] {
        OCIO::ColorSpaceTransformRcPtr to_aces = OCIO::ColorSpaceTransform::Create();
        to_aces->setSrc(space.c_str());
        to_aces->setDst("aces_interchange");
        OCIO::BuiltinTransformRcPtr to_xyz = OCIO::BuiltinTransform::Create();
        to_xyz->setStyle("UTILITY - ACES-AP0_to_CIE-XYZ-D65_BFD");
        OCIO::GroupTransformRcPtr g = OCIO::GroupTransform::Create();
        g->appendTransform(to_aces);
        g->appendTransform(to_xyz);
        return impl_->config->getProcessor(g);
      },
      fmt::format("'{}' to CIE XYZ", space));
  std::vector<float> out;
  constexpr float kPrimariesAndWhite[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  for (const auto& rgb : kPrimariesAndWhite) {
    float xyz[3] = {rgb[0], rgb[1], rgb[2]};
    cpu->applyRGB(xyz);
    const float sum = xyz[0] + xyz[1] + xyz[2];
    if (!(sum > 0.0f)) return {};
    out.push_back(xyz[0] / sum);
    out.push_back(xyz[1] / sum);
  }
  return out;
}

bool Config::is_identity(const std::string& src, const std::string& dst) const {
  const std::string a = resolve(src), b = resolve(dst);
  return a == b || is_data(a) || is_data(b);
}

void Config::convert(ImageView<float> image, const std::string& src, const std::string& dst) const {
  if (is_identity(src, dst)) return;
  impl_
      ->conversion(
          src + '\n' + dst, [&] { return impl_->config->getProcessor(src.c_str(), dst.c_str()); },
          fmt::format("'{}' to '{}'", src, dst))
      ->apply(image);
}

void Config::to_display(ImageView<float> image, const std::string& src, const std::string& display,
                        const std::string& view) const {
  const std::string space = view_space(display, view);
  if (!space.empty() && is_identity(src, space)) return;
  const auto steps = impl_->conversion(
      src + '\n' + display + '\n' + view + "\nview",
      [&] {
        OCIO::DisplayViewTransformRcPtr t = OCIO::DisplayViewTransform::Create();
        t->setSrc(src.c_str());
        t->setDisplay(display.c_str());
        t->setView(view.c_str());
        return impl_->config->getProcessor(t);
      },
      fmt::format("'{}' to display '{}', view '{}'", src, display, view));
  steps->apply(image);
}

}  // namespace emaki::colour
