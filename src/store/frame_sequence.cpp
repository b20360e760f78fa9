#include "store/frame_sequence.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>

#include "core/error.h"
#include "core/limits.h"
#include "io/image_io.h"
#include "store/studio_passes.h"

namespace emaki::io {

std::string frame_file(const std::string& pattern, int frame) {
  std::string out;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') {
      out += pattern[i];
      continue;
    }
    std::size_t j = i + 1;
    int width = 0;
    while (j < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[j]))) {
      width = width * 10 + (pattern[j++] - '0');
      // Checked per digit, so the width never overflows an int either.
      if (width > kMaxFrameWidth)
        throw Error(Error::Field{"sequence"},
                    fmt::format("'{}': the frame number's width must be at most {}", echo(pattern),
                                kMaxFrameWidth));
    }
    out += fmt::format("{:0{}d}", frame, width);
    i = j;  // at the 'd'
  }
  return out;
}

std::vector<std::string> source_channels(const pipeline::Source& source,
                                         const render::PassInfo& pass) {
  for (const auto& m : source.channels)
    if (m.pass == pass.name) return m.channels;
  std::vector<std::string> names;
  for (int c = 0; c < pass.count; ++c)
    names.push_back(fmt::format("{}.{}", pass.name, pass.suffixes[c]));
  return names;
}

Image<float> read_pass_file(const std::string& file, pipeline::SourcePreset preset,
                            const std::string& view_layer) {
  if (preset == pipeline::SourcePreset::kBlender) {
    const Image<float> raw = read_image_float(file, ReadOptions{blender_channels(view_layer)});
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    add_blender_bounds(raw.cview(), lo, hi);
    return blender_to_emaki(raw.cview(), cube_around(lo, hi), file);
  }
  const std::vector<std::string> have = list_channels(file);
  std::vector<std::string> names;
  for (const render::PassInfo& p : render::pass_table())
    for (int c = 0; c < p.count; ++c) {
      const std::string name = fmt::format("{}.{}", p.name, p.suffixes[c]);
      const bool found = std::find(have.begin(), have.end(), name) != have.end();
      names.push_back(found || p.count > 1 ? name : std::string(p.name) + ".V");
    }
  return read_image_float(file, ReadOptions{names});
}

namespace {

class SequenceFrames : public pipeline::FrameSource {
 public:
  explicit SequenceFrames(const pipeline::Source& s) : source_(s) {
    if (s.preset == pipeline::SourcePreset::kBlender) {
      raw_ = blender_channels(s.view_layer);
      for (const auto& m : s.channels)
        for (const std::string& c : m.channels) channels_.push_back(c);
      // position_norm's cube: every frame's covered positions, so it is fixed for the shot.
      glm::vec3 lo(INFINITY), hi(-INFINITY);
      for (int f = s.first_frame; f <= s.last_frame; ++f) {
        const Image<float> raw = read_raw(frame_file(s.pattern, f));
        add_blender_bounds(raw.cview(), lo, hi);
      }
      cube_ = cube_around(lo, hi);
      return;
    }
    for (const render::PassInfo& p : render::pass_table())
      for (const std::string& c : source_channels(s, p)) channels_.push_back(c);
  }
  Image<float> passes(int frame) const override {
    const std::string file = frame_file(source_.pattern, frame);
    if (source_.preset != pipeline::SourcePreset::kBlender) {
      Image<float> frame = read_checked(file, channels_);
      apply_conventions(frame, {source_.world_normals, source_.z_up, source_.premultiplied}, file);
      return frame;
    }
    Image<float> out = blender_to_emaki(read_raw(file).cview(), cube_, file);
    // Passes mapped in source.channels are read as they are, over the converted ones.
    if (!channels_.empty()) {
      const Image<float> mapped = read_checked(file, channels_);
      int k = 0;
      for (const auto& m : source_.channels) {
        const render::PassInfo* p = render::find_pass(m.pass);
        for (int c = 0; c < p->count; ++c, ++k)
          for (int y = 0; y < out.height(); ++y)
            for (int x = 0; x < out.width(); ++x) out(x, y, p->first + c) = mapped(x, y, k);
      }
    }
    return out;
  }

 private:
  Image<float> read_checked(const std::string& file, const std::vector<std::string>& ch) const {
    Image<float> img = read_image_float(file, ReadOptions{ch});
    if (img.width() != source_.width || img.height() != source_.height)
      throw Error(file, fmt::format("is {}x{}, the sequence's first frame is {}x{}", img.width(),
                                    img.height(), source_.width, source_.height));
    return img;
  }
  Image<float> read_raw(const std::string& file) const { return read_checked(file, raw_); }

  pipeline::Source source_;
  std::vector<std::string> channels_;  // emaki: every pass; blender: the mapped passes only
  std::vector<std::string> raw_;       // blender: blender_channels()
  Cube cube_;
};

}  // namespace

std::unique_ptr<pipeline::FrameSource> open_sequence(const pipeline::Source& source) {
  return std::make_unique<SequenceFrames>(source);
}

}  // namespace emaki::io
