#include "apps/emaki/index_cache.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "core/error.h"
#include "core/fnv.h"

namespace emaki::app {

namespace {

std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return {};
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(f), {});
}

uint64_t add_bytes(uint64_t h, const std::vector<uint8_t>& b) {
  h = fnv1a_add(h, uint32_t(b.size()));
  for (uint8_t v : b) h = fnv1a_add(h, v);
  return h;
}

}  // namespace

std::string index_cache_path(const SynthArgs& args) {
  uint64_t h = add_bytes(kFnvOffset, read_bytes(args.style_path));
  h = fnv1a(fmt::format("{} {} {}", args.style_weight, args.params.patch_size, args.params.index_k),
            h);
  for (const SynthGuideArg& g : args.guides)
    h = fnv1a(fmt::format(" {}", g.weight), add_bytes(h, read_bytes(g.source)));
  return (std::filesystem::path(args.index_cache) / fmt::format("{:016x}.emaki-index", h)).string();
}

std::shared_ptr<const synth::ExemplarIndex> load_cached_index(const std::string& path, bool quiet) {
  const std::vector<uint8_t> bytes = read_bytes(path);
  if (bytes.empty()) return nullptr;
  try {
    return std::make_shared<const synth::ExemplarIndex>(
        synth::deserialize_index(bytes.data(), bytes.size(), path));
  } catch (const Error& e) {
    if (!quiet) std::fprintf(stderr, "emaki synth: %s; building the index anew\n", e.what());
    return nullptr;
  }
}

void store_cached_index(const std::string& path, const synth::ExemplarIndex& index) {
  const std::vector<uint8_t> bytes = synth::serialize_index(index);
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
  const std::string tmp = fmt::format("{}.tmp{}", path, getpid());
  {
    std::ofstream f(tmp, std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    if (!f) {
      std::filesystem::remove(tmp, ec);
      throw Error("--index-cache", fmt::format("cannot write {}", tmp));
    }
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw Error("--index-cache", fmt::format("cannot write {}", path));
  }
}

}  // namespace emaki::app
