// The file side of running a shot: the frames of its source (rendered from a glTF scene, or
// read from a studio render's EXR sequence), its exemplars and paper, and the Store that keeps
// layer results and per-frame outputs in the output folder (every write atomic), plus the
// previews made at the end (contact sheet, MP4 through ffmpeg).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "io/output_store.h"
#include "pipeline/frames.h"
#include "pipeline/run.h"
#include "pipeline/shot.h"
#include "render/passes.h"

namespace emaki::io {

// The widest frame number a pattern may ask for (%012d): wider is refused, never padded.
inline constexpr int kMaxFrameWidth = 12;

// The file of frame `frame` of a printf-style pattern ("frame_%04d.exr"); the pattern holds %d
// or %0Nd only (the shot file checks it), and a width over kMaxFrameWidth throws.
std::string frame_file(const std::string& pattern, int frame);

// The channel names a sequence source reads for `pass` (its mapping, or emaki's own names).
std::vector<std::string> source_channels(const pipeline::Source& source,
                                         const render::PassInfo& pass);

// One pass file as emaki's frame (render::kChannelCount channels): `preset` "emaki" reads
// emaki's channel names (a single-channel pass also as NAME.V, as the Blender exporter writes
// it); "blender" converts a plain Blender render of view layer `view_layer`, position_norm's
// cube taken from this frame alone.
Image<float> read_pass_file(const std::string& file, const std::string& preset = "emaki",
                            const std::string& view_layer = "ViewLayer");

// The shot's frames. Errors name the shot file's keys (source.scene, source.clip, ...).
std::unique_ptr<pipeline::FrameSource> open_frames(const pipeline::Shot& shot);

// Every exemplar's painting and guide passes; errors name exemplars.NAME.*.
std::map<std::string, pipeline::ExemplarImages> load_exemplars(const pipeline::Shot& shot);

pipeline::CompositeInputs load_composite_inputs(const pipeline::Shot& shot);

// The output folder's layout.
struct OutputPaths {
  std::string folder;
  std::string layer_exr(const std::string& layer, int frame) const;
  std::string layer_png(const std::string& layer, int frame) const;
  std::string composite_png(int frame) const;
  std::string composite_exr(int frame) const;
  std::string layered_exr(int frame) const;
  std::string mp4() const;
  std::string contact_sheet() const;
};

enum class StoreMode {
  kRun,           // layers made with other settings are redone (emaki run)
  kReadFinished,  // they are an error naming the layer (emaki composite, qa flicker)
};

// Layer frames and composited frames each carry a manifest of the settings that made them
// (io/shot_manifest.h). Files made under other settings are never read back: `kRun` deletes
// and redoes them on the first write, `kReadFinished` throws emaki::Error naming the folder.
class FileStore : public pipeline::Store {
 public:
  // Creates the folders, locks the output folder (emaki::Error naming the holder when another
  // emaki has it) and removes temporary files a killed run left behind.
  explicit FileStore(const pipeline::Shot& shot, StoreMode mode = StoreMode::kRun);
  ~FileStore() override;
  bool has_layer(const pipeline::Layer& layer, int frame) const override;
  Image<float> read_layer(const pipeline::Layer& layer, int frame) const override;
  void write_layer(const pipeline::Layer& layer, int frame, ImageView<const float> value) override;
  bool has_frame(int frame) const override;
  void write_frame(int frame, ImageView<const float> composite,
                   const std::vector<ImageView<const float>>& layers,
                   ImageView<const float> passes) override;
  const OutputPaths& paths() const { return paths_; }

 private:
  struct Manifested {
    Manifest want;         // the settings of the shot as it is now
    bool current = false;  // the files on disk were made with them
    std::string stale;     // !current and something is there: what changed
  };
  const Manifested& layer_state(const pipeline::Layer& layer) const;

  const pipeline::Shot& shot_;
  StoreMode mode_;
  OutputPaths paths_;
  std::unique_ptr<FolderLock> lock_;
  std::map<std::string, Manifested> layers_;
  Manifested frames_;
};

// The contact sheet and the MP4 preview of the composited frames [first, last] (each when the
// shot's outputs ask for it). Returns the files written.
std::vector<std::string> write_previews(const pipeline::Shot& shot, int first, int last);

// Encodes `pattern` (printf-style) frames [first, ...] into an H.264 MP4 with the ffmpeg binary.
void encode_mp4(const std::string& pattern, int first, float fps, int crf, const std::string& out);

}  // namespace emaki::io
