// A shot's inputs kept in memory between runs while its files are being edited (emaki lookdev):
// decoded images (paintings, weight maps, the paper) under the digest of their file's bytes,
// the guides the layers cut out of an exemplar's passes (a MatCap-like exemplar's reference
// passes, under what they are rendered from; a pass file, under its digest), and a glTF scene's
// guide passes per frame under every setting that decides them
// (store/settings_manifests.h passes_manifest, which names the scene's digest). An entry is
// taken only when its key matches, so a run with the cache writes what a run without it writes,
// byte for byte; a saved painting misses and is decoded again, the rest is reused. What a run
// did not use is dropped when it ends (an old painting does not stay behind).
//
// One run at a time: the cache is not shared between threads.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>

#include "core/image.h"
#include "pipeline/frames.h"

namespace emaki::shot {

class InputCache {
 public:
  struct Frames;  // the scene's frames and the passes they rendered (input_cache.cpp)

  InputCache();
  ~InputCache();
  InputCache(const InputCache&) = delete;
  InputCache& operator=(const InputCache&) = delete;

  // The image under `key`, or null. A found entry is kept past the next drop_unused().
  std::shared_ptr<const Image<float>> find(const std::string& key);
  std::shared_ptr<const Image<float>> keep(const std::string& key, Image<float> image);

  // The frames of the scene whose settings are `settings` (the passes manifest's text), opened
  // by `open` when the settings changed; their passes are kept per frame.
  std::unique_ptr<pipeline::FrameSource> frames(
      const std::string& settings,
      const std::function<std::unique_ptr<pipeline::FrameSource>()>& open);

  // Forgets what was not found or kept since the last call.
  void drop_unused();

  // Entries held now (images and frames' passes), for tests.
  std::size_t size() const;

 private:
  std::map<std::string, std::shared_ptr<const Image<float>>> m_images;
  std::set<std::string> m_used;  // found or kept since the last drop_unused
  std::string m_settings;
  std::shared_ptr<Frames> m_frames;
};

}  // namespace emaki::shot
