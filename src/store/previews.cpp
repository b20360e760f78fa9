#include "store/previews.h"

#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>

#include "core/error.h"
#include "core/shot_keys.h"
#include "io/image_io.h"
#include "pipeline/run.h"
#include "store/file_store.h"
#include "store/settings_manifests.h"

extern char** environ;

namespace emaki::io {

namespace fs = std::filesystem;
using pipeline::Shot;

void encode_mp4(const std::string& pattern, int first, float fps, int crf, const std::string& out) {
  // Created exclusively beside the target; ffmpeg then writes the file we made (commit checks
  // that it still is).
  TempFile tmp_file(out, shot_keys::kOutputsMp4);
  const std::string tmp = tmp_file.path();
  std::vector<std::string> args = {"ffmpeg", "-nostdin", "-y", "-loglevel", "error", "-framerate",
                                   fmt::format("{}", fps), "-start_number", std::to_string(first),
                                   "-i", pattern, "-c:v", "libx264", "-pix_fmt", "yuv420p", "-crf",
                                   std::to_string(crf),
                                   // yuv420p needs even sizes.
                                   "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", tmp};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, "ffmpeg", nullptr, nullptr, argv.data(), environ) != 0)
    throw Error(shot_keys::kOutputsMp4, "cannot run 'ffmpeg' (is it installed and on PATH?)");
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw Error(shot_keys::kOutputsMp4, fmt::format("ffmpeg failed encoding '{}'", pattern));
  tmp_file.commit();
}

std::vector<std::string> write_previews(const Shot& shot, int first, int last) {
  std::vector<std::string> written;
  const OutputPaths paths{shot.outputs.folder};
  std::error_code ec;
  // Frames composited under other settings (a killed run after a resize) are not previewed.
  const auto made =
      read_manifest((fs::path(shot.outputs.folder) / "composite" / kManifest).string());
  if (!made || !manifest_current(*made, frames_manifest(shot))) return written;
  for (int f = first; f <= last; ++f)
    if (!fs::is_regular_file(paths.composite_png(f), ec)) return written;  // not all composited
  if (shot.outputs.contact_sheet && shot.outputs.composite_png) {
    // At most 12 frames, spread over the shot.
    const int count = std::min(12, last - first + 1);
    std::vector<Image<float>> thumbs;
    for (int i = 0; i < count; ++i) {
      const int f = count == 1 ? first : first + int((long(last - first) * i) / (count - 1));
      const std::string file = paths.composite_png(f);
      thumbs.push_back(read_image_float(file));
      const Image<float>& t = thumbs.back();
      if (t.width() != shot.source.width || t.height() != shot.source.height)
        throw Error(file, fmt::format("is {}x{}, the shot makes {}x{}; {}", t.width(), t.height(),
                                      shot.source.width, shot.source.height, kRedoHint));
    }
    const Image<float> sheet = pipeline::contact_sheet(thumbs, 4, 320);
    WriteOptions wo;
    wo.format = SampleFormat::kU8;
    write_image(paths.contact_sheet(), sheet.cview(), wo);
    written.push_back(paths.contact_sheet());
  }
  if (shot.outputs.mp4) {
    // ffmpeg reads % anywhere in an image-sequence path as a pattern: the folder's are doubled.
    std::string folder;
    for (const char c : shot.outputs.folder)
      folder += c == '%' ? std::string("%%") : std::string(1, c);
    encode_mp4(folder + "/composite/frame_%04d.png", first, shot.source.fps, shot.outputs.crf,
               paths.mp4());
    written.push_back(paths.mp4());
  }
  return written;
}

}  // namespace emaki::io
