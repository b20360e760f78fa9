#include "shot/input_cache.h"

#include <mutex>

namespace emaki::shot {

// The frames' source and the passes it rendered, shared with every FrameSource handed out: a run
// may outlive a later change of settings that replaces them in the cache.
struct InputCache::Frames {
  std::unique_ptr<pipeline::FrameSource> source;
  std::mutex mutex;
  std::map<int, Image<float>> passes;
};

namespace {

class KeptFrames : public pipeline::FrameSource {
 public:
  explicit KeptFrames(std::shared_ptr<InputCache::Frames> frames) : m_frames(std::move(frames)) {}
  Image<float> passes(int frame) const override;
  // Not kept here: the source reads them from the pass cache each time, in about a millisecond.
  std::vector<pipeline::KeptField> kept_fields(int frame) const override {
    return m_frames->source->kept_fields(frame);
  }

 private:
  std::shared_ptr<InputCache::Frames> m_frames;
};

}  // namespace

Image<float> KeptFrames::passes(int frame) const {
  InputCache::Frames& f = *m_frames;
  const std::lock_guard lock(f.mutex);
  auto it = f.passes.find(frame);
  if (it == f.passes.end()) it = f.passes.emplace(frame, f.source->passes(frame)).first;
  return it->second.clone();
}

InputCache::InputCache() = default;
InputCache::~InputCache() = default;

std::shared_ptr<const Image<float>> InputCache::find(const std::string& key) {
  const auto it = m_images.find(key);
  if (it == m_images.end()) return nullptr;
  m_used.insert(key);
  return it->second;
}

std::shared_ptr<const Image<float>> InputCache::keep(const std::string& key, Image<float> image) {
  m_used.insert(key);
  auto kept = std::make_shared<const Image<float>>(std::move(image));
  m_images.insert_or_assign(key, kept);
  return kept;
}

std::unique_ptr<pipeline::FrameSource> InputCache::frames(
    const std::string& settings,
    const std::function<std::unique_ptr<pipeline::FrameSource>()>& open) {
  if (!m_frames || settings != m_settings) {
    auto f = std::make_shared<Frames>();
    f->source = open();
    m_frames = std::move(f);
    m_settings = settings;
  }
  return std::make_unique<KeptFrames>(m_frames);
}

void InputCache::drop_unused() {
  for (auto it = m_images.begin(); it != m_images.end();)
    it = m_used.count(it->first) ? std::next(it) : m_images.erase(it);
  m_used.clear();
}

std::size_t InputCache::size() const {
  std::size_t n = m_images.size();
  if (m_frames) {
    const std::lock_guard lock(m_frames->mutex);
    n += m_frames->passes.size();
  }
  return n;
}

}  // namespace emaki::shot
