#include "apps/emaki/frame_range.h"

#include <fmt/format.h>

#include <charconv>
#include <cstdint>
#include <optional>
#include <string_view>

#include "core/error.h"
#include "core/limits.h"

namespace emaki::app {
namespace {

// A frame number: ASCII digits only (no sign, space or '+', which stoll would let through), or
// nothing when it does not parse or does not fit in 64 bits.
std::optional<int64_t> parse_frame(std::string_view s) {
  if (s.empty() || s.front() < '0' || s.front() > '9') return std::nullopt;
  int64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

}  // namespace

FrameRange parse_frame_range(const std::string& option, const std::string& text) {
  const std::string_view t = text;
  const std::size_t dash = t.find('-');
  const std::optional<int64_t> a = parse_frame(t.substr(0, dash));
  const std::optional<int64_t> b =
      dash == std::string_view::npos ? a : parse_frame(t.substr(dash + 1));
  if (!a || !b || *a > *b || *b > kMaxFrame || *b - *a >= kMaxFrameCount)
    throw Error(option, fmt::format("expects FIRST-LAST or FRAME (frame numbers in [0, {}], "
                                    "FIRST <= LAST, at most {} frames), got '{}'",
                                    kMaxFrame, kMaxFrameCount, echo(text)));
  return {int(*a), int(*b)};
}

}  // namespace emaki::app
