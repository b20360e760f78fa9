#include "colour/steps.h"

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>

#include "core/parallel.h"

namespace emaki::colour {

namespace OCIO = OCIO_NAMESPACE;

namespace {

// The tables' points: |x| in [2^-32, 2^32), 2^10 points per octave (the float's bits shifted by
// kShift), plus the end point 2^32.
constexpr uint32_t kShift = 13;
constexpr uint32_t kLow = uint32_t(127 - 32) << 23;   // the bits of 2^-32
constexpr uint32_t kHigh = uint32_t(127 + 32) << 23;  // the bits of 2^32
constexpr uint32_t kPoints = ((kHigh - kLow) >> kShift) + 1;
constexpr float kFraction = 1.0f / float(1u << kShift);

bool is_curve(OCIO::TransformType t) {
  switch (t) {
    case OCIO::TRANSFORM_TYPE_LOG:
    case OCIO::TRANSFORM_TYPE_LOG_AFFINE:
    case OCIO::TRANSFORM_TYPE_LOG_CAMERA:
    case OCIO::TRANSFORM_TYPE_EXPONENT:
    case OCIO::TRANSFORM_TYPE_EXPONENT_WITH_LINEAR:
    case OCIO::TRANSFORM_TYPE_GRADING_RGB_CURVE:
      return true;
    default:
      return false;
  }
}

// What a table may hold: curves, and the matrices and ranges between them when they keep the
// channels apart (a lookup table's linear pieces, a 3D LUT or a fixed function stay OCIO's).
bool may_table(const OCIO::ConstConfigRcPtr& config, const OCIO::ConstTransformRcPtr& t) {
  const OCIO::TransformType type = t->getTransformType();
  if (!is_curve(type) && type != OCIO::TRANSFORM_TYPE_MATRIX && type != OCIO::TRANSFORM_TYPE_RANGE)
    return false;
  return !config->getProcessor(t)->hasChannelCrosstalk();
}

void apply_processor(const OCIO::ConstCPUProcessorRcPtr& cpu, ImageView<float> image, int y0,
                     int y1) {
  const std::ptrdiff_t pixel = std::ptrdiff_t(image.channels) * std::ptrdiff_t(sizeof(float));
  const std::ptrdiff_t row = image.stride * std::ptrdiff_t(sizeof(float));
  OCIO::PackedImageDesc desc(image.row(y0), image.width, y1 - y0, OCIO::CHANNEL_ORDERING_RGB,
                             OCIO::BIT_DEPTH_F32, sizeof(float), pixel, row);
  cpu->apply(desc);
}

}  // namespace

struct Steps::Step {
  OCIO::ConstCPUProcessorRcPtr cpu;  // the step itself, or a table's values outside its range
  bool table = false;
  // values[channel][sign]: kPoints values; zero[channel][sign]: the value at +-0.
  std::array<std::array<std::vector<float>, 2>, 3> values;
  std::array<std::array<float, 2>, 3> zero{};

  // Fills the tables from `cpu`; false (no table) when a value is not finite.
  bool fill() {
    std::vector<float> rgb;
    rgb.reserve(std::size_t(2 * kPoints + 2) * 3);
    for (uint32_t sign = 0; sign < 2; ++sign) {
      for (uint32_t i = 0; i < kPoints; ++i) {
        const float x = std::bit_cast<float>((sign << 31) | (kLow + (i << kShift)));
        rgb.insert(rgb.end(), {x, x, x});
      }
      const float z = std::bit_cast<float>(sign << 31);
      rgb.insert(rgb.end(), {z, z, z});
    }
    const long n = long(rgb.size() / 3);
    OCIO::PackedImageDesc desc(rgb.data(), n, 1, 3);
    cpu->apply(desc);
    for (float v : rgb)
      if (!std::isfinite(v)) return false;
    for (int c = 0; c < 3; ++c)
      for (uint32_t sign = 0; sign < 2; ++sign) {
        const float* first = rgb.data() + std::size_t(sign) * (kPoints + 1) * 3;
        std::vector<float>& v = values[c][sign];
        v.resize(kPoints);
        for (uint32_t i = 0; i < kPoints; ++i) v[i] = first[std::size_t(i) * 3 + c];
        zero[c][sign] = first[std::size_t(kPoints) * 3 + c];
      }
    table = true;
    return true;
  }

  // Channel c's value for x; false when x is outside the table.
  bool lookup(int c, float x, float& out) const {
    const uint32_t bits = std::bit_cast<uint32_t>(x);
    const uint32_t sign = bits >> 31, magnitude = bits & 0x7fffffffu;
    if (magnitude - kLow >= kHigh - kLow) {
      if (magnitude != 0) return false;
      out = zero[c][sign];
      return true;
    }
    const uint32_t offset = magnitude - kLow;
    const float* v = values[c][sign].data() + (offset >> kShift);
    const float t = float(offset & ((1u << kShift) - 1)) * kFraction;
    out = v[0] + t * (v[1] - v[0]);
    return true;
  }

  void apply(ImageView<float> image, int y0, int y1) const {
    if (!table) return apply_processor(cpu, image, y0, y1);
    // Pixels outside the table: gathered, converted by OpenColorIO, put back.
    std::vector<float*> outside;
    std::vector<float> rgb;
    for (int y = y0; y < y1; ++y) {
      float* p = image.row(y);
      for (int x = 0; x < image.width; ++x, p += image.channels) {
        float out[3];
        if (lookup(0, p[0], out[0]) && lookup(1, p[1], out[1]) && lookup(2, p[2], out[2])) {
          p[0] = out[0];
          p[1] = out[1];
          p[2] = out[2];
        } else {
          outside.push_back(p);
          rgb.insert(rgb.end(), {p[0], p[1], p[2]});
        }
      }
    }
    if (outside.empty()) return;
    OCIO::PackedImageDesc desc(rgb.data(), long(outside.size()), 1, 3);
    cpu->apply(desc);
    for (std::size_t i = 0; i < outside.size(); ++i)
      for (int c = 0; c < 3; ++c) outside[i][c] = rgb[i * 3 + std::size_t(c)];
  }
};

Steps::Steps(const OCIO::ConstConfigRcPtr& config, const OCIO::ConstProcessorRcPtr& processor) {
  // A processor whose values can change after it is made (dynamic properties) keeps no table;
  // nor does one that cannot be cut (an op OpenColorIO cannot turn back into a transform).
  // With no table (or none allowed), the processor as it is, one step.
  if (!processor->isDynamic()) {
    try {
      if (cut(config, processor)) return;
    } catch (const OCIO::Exception&) {
      // the whole processor, below
    }
  }
  steps_.clear();
  auto step = std::make_unique<Step>();
  step->cpu = processor->getDefaultCPUProcessor();
  steps_.push_back(std::move(step));
}

bool Steps::cut(const OCIO::ConstConfigRcPtr& config, const OCIO::ConstProcessorRcPtr& processor) {
  const OCIO::GroupTransformRcPtr all =
      processor->getOptimizedProcessor(OCIO::OPTIMIZATION_DEFAULT)->createGroupTransform();
  const int n = all->getNumTransforms();
  std::vector<bool> tableable(std::size_t(n), false);
  for (int i = 0; i < n; ++i) tableable[std::size_t(i)] = may_table(config, all->getTransform(i));
  // Runs of transforms that may be tabled and hold a curve become tables; the transforms
  // between them (from pending_first on), processors.
  int pending_first = 0;
  auto group_of = [&](int a, int b) {
    OCIO::GroupTransformRcPtr g = OCIO::GroupTransform::Create();
    for (int i = a; i < b; ++i) g->appendTransform(all->getTransform(i)->createEditableCopy());
    return g;
  };
  auto flush = [&](int end) {
    if (end > pending_first) {
      auto step = std::make_unique<Step>();
      step->cpu = config->getProcessor(group_of(pending_first, end))->getDefaultCPUProcessor();
      steps_.push_back(std::move(step));
    }
  };
  for (int i = 0; i < n;) {
    int j = i;
    bool curve = false;
    for (; j < n && tableable[std::size_t(j)]; ++j)
      if (is_curve(all->getTransform(j)->getTransformType())) curve = true;
    if (j > i && curve) {
      auto step = std::make_unique<Step>();
      step->cpu = config->getProcessor(group_of(i, j))->getDefaultCPUProcessor();
      if (step->fill()) {
        flush(i);
        steps_.push_back(std::move(step));
        pending_first = j;
      }
    }
    i = std::max(j, i + 1);
  }
  if (pending_first == 0) return false;  // no table
  flush(n);
  return true;
}

Steps::~Steps() = default;

void Steps::apply(ImageView<float> image) const {
  if (image.empty()) return;
  parallel_rows(image.height, 16, [&](int y0, int y1) {
    for (const auto& step : steps_) step->apply(image, y0, y1);
  });
}

int Steps::table_steps() const {
  int n = 0;
  for (const auto& s : steps_) n += s->table ? 1 : 0;
  return n;
}

int Steps::processor_steps() const {
  return int(steps_.size()) - table_steps();
}

}  // namespace emaki::colour
